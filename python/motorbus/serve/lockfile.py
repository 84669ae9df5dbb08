"""Finding the service of a bench: a lock file next to the bench file.

``motorbus serve BENCH`` holds ``<dir of BENCH>/.<file name>.serve.lock`` with an
exclusive ``flock`` for as long as it runs, and writes a :class:`ServiceInfo` into it
as JSON.  The lock is the kernel's (the pattern of ``sim.py``'s ``_claim_link_dir``):
a service that died, even by SIGKILL, holds nothing, and the stale file it leaves
blocks no later service.  :func:`find_service` reports a service only when a live
process holds the lock *and* its socket exists.

The RPC socket cannot sit next to the bench file: ``sun_path`` holds 108 bytes, and a
bench in a deep directory would not fit.  It goes under ``$XDG_RUNTIME_DIR/motorbus``
(a per-user tmpfs) or ``/tmp/motorbus-<uid>``, named by a hash of the bench file's real
path (:func:`default_socket_path`).
"""
from __future__ import annotations

import dataclasses
import errno
import fcntl
import hashlib
import json
import os
import time
from dataclasses import dataclass, field
from typing import Any, Optional

from .. import _core

__all__ = ["ServiceInfo", "ServedElsewhere", "ServiceLock", "lock_path", "find_service", "default_socket_path",
           "served_link", "running_services", "SUN_PATH_MAX"]

#: Bytes a Unix socket path may have (Linux ``sockaddr_un.sun_path`` is 108, with its NUL).
SUN_PATH_MAX = 107
#: The largest lock file read back (a ServiceInfo is well under 2 kB; a bigger file is not ours).
_MAX_INFO_BYTES = 64 * 1024


class ServedElsewhere(_core.MotorbusError):
    """The bench is owned by a running ``motorbus serve``: something that needs the
    bench's transports (a second service, a protocol console, raw SDO, a bus dump) is
    refused.  ``pid``: the service's process; ``bench``: the bench file."""

    def __init__(self, bench: str, pid: int, what: str) -> None:
        self.bench, self.pid, self.what = bench, pid, what
        super().__init__(f"{bench} is served by motorbus serve (pid {pid}): {what} needs the transports; "
                         f"stop the service first")


@dataclass
class ServiceInfo:
    """What a running service tells other programs (the lock file's JSON)."""

    pid: int
    bench: str                       # realpath of the bench file
    socket: str                      # Unix socket of the RPC face
    sim: bool = False
    prefix: Optional[str] = None     # CA prefix (None: served without EPICS)
    ca_port: Optional[int] = None
    interfaces: list = field(default_factory=list)
    env: dict = field(default_factory=dict)    # what a CA client on this host sets
    links: list = field(default_factory=list)  # the bus specs and serial ports it holds (raw access refused)
    http: Optional[str] = None       # the web page's URL (None: served without --http)

    def to_json(self) -> str:
        return json.dumps(dataclasses.asdict(self), indent=1, sort_keys=True)

    @classmethod
    def from_json(cls, text: str) -> "ServiceInfo":
        data = json.loads(text)
        if not isinstance(data, dict):
            raise ValueError("not a JSON object")
        names = {f.name for f in dataclasses.fields(cls)}
        info = cls(**{k: v for k, v in data.items() if k in names})
        if not isinstance(info.pid, int) or not isinstance(info.socket, str) or not isinstance(info.bench, str):
            raise ValueError("pid, socket or bench of the wrong type")
        return info


def _real(bench_path: Any) -> str:
    return os.path.realpath(os.fspath(bench_path))


def lock_path(bench_path: Any) -> str:
    """``<dir>/.<file name>.serve.lock`` of the bench file (its real path: a symlink to a
    bench file finds the service of the file it points to)."""
    real = _real(bench_path)
    d, name = os.path.split(real)
    return os.path.join(d, f".{name}.serve.lock")


def _runtime_dir() -> str:
    xdg = os.environ.get("XDG_RUNTIME_DIR")
    if xdg and os.path.isdir(xdg) and os.access(xdg, os.W_OK | os.X_OK):
        return os.path.join(xdg, "motorbus")
    return os.path.join("/tmp", f"motorbus-{os.getuid()}")


def default_socket_path(bench_path: Any) -> str:
    """The RPC socket of the bench's service: ``<runtime dir>/<16 hex of sha256(realpath)>.sock``
    (made short enough for ``sun_path`` whatever the bench's directory)."""
    digest = hashlib.sha256(_real(bench_path).encode()).hexdigest()[:16]
    return os.path.join(_runtime_dir(), f"{digest}.sock")


def check_socket_path(path: str) -> str:
    """A socket path that fits ``sun_path``, its directory created (0700: the socket
    commands motors; other users have no business with it)."""
    if len(os.fsencode(path)) > SUN_PATH_MAX:
        raise _core.InvalidArgument(f"socket path {path!r} is {len(os.fsencode(path))} bytes: a Unix socket "
                                    f"path holds at most {SUN_PATH_MAX} (give a shorter --socket)")
    d = os.path.dirname(os.path.abspath(path))
    os.makedirs(d, mode=0o700, exist_ok=True)
    if os.path.abspath(d) == os.path.abspath(_runtime_dir()):
        # /tmp/motorbus-<uid> is a name anyone could take first: only our own private
        # directory may hold a socket other programs send motor commands to.
        st = os.stat(d)
        if st.st_uid != os.getuid() or st.st_mode & 0o077:
            raise _core.InvalidArgument(f"{d} (where the service's socket goes) is not a private directory of "
                                        f"this user (owner uid {st.st_uid}, mode {st.st_mode & 0o777:o}): remove "
                                        f"it, or give --socket PATH")
    return path


def _read_info(fd: int) -> Optional[ServiceInfo]:
    try:
        raw = os.pread(fd, _MAX_INFO_BYTES, 0)
        return ServiceInfo.from_json(raw.decode()) if raw.strip() else None
    except (OSError, ValueError, TypeError, UnicodeDecodeError):
        return None


def _holder_pid(fd: int) -> str:
    info = _read_info(fd)
    if info is not None:
        return str(info.pid)
    try:   # the service writes its pid first, its info once its faces are up
        text = os.pread(fd, 32, 0).decode(errors="replace").strip()
    except OSError:
        text = ""
    return text if text.isdigit() else "?"


class ServiceLock:
    """The service's hold on its bench: ``acquire()`` takes the flock (or raises
    ServedElsewhere naming the holder), ``publish(info)`` writes the JSON, ``release()``
    empties and unlocks it.  The file stays: removing it could race a new service that
    already opened it; an unlocked file means no service."""

    def __init__(self, bench_path: Any) -> None:
        self.bench = _real(bench_path)
        self.path = lock_path(bench_path)
        self._fd: Optional[int] = None

    def acquire(self) -> None:
        try:
            fd = os.open(self.path, os.O_RDWR | os.O_CREAT | os.O_CLOEXEC, 0o644)
        except OSError as e:
            raise _core.InvalidArgument(f"{self.bench}: cannot create the service's lock file {self.path}: "
                                        f"{e.strerror} (the bench file's directory must be writable)") from None
        for attempt in range(6):
            try:
                fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
                break
            except BlockingIOError:
                # find_service's test lock lasts microseconds: only a lock that stays is a service.
                if attempt < 5:
                    time.sleep(0.01)
        else:
            holder = _holder_pid(fd)
            os.close(fd)
            raise ServedElsewhere(self.bench, int(holder) if holder.isdigit() else -1,
                                  "a second motorbus serve") from None
        os.ftruncate(fd, 0)
        os.pwrite(fd, f"{os.getpid()}\n".encode(), 0)
        self._fd = fd

    def publish(self, info: ServiceInfo) -> None:
        if self._fd is None:
            raise _core.ClosedError("ServiceLock.publish: the lock is not held")
        data = (info.to_json() + "\n").encode()
        os.ftruncate(self._fd, 0)
        os.pwrite(self._fd, data, 0)

    def release(self) -> None:
        fd, self._fd = self._fd, None
        if fd is None:
            return
        try:
            os.ftruncate(fd, 0)
        except OSError:
            pass
        os.close(fd)      # closing the descriptor releases the flock

    @property
    def held(self) -> bool:
        return self._fd is not None


def _index_entry(bench_path: Any) -> str:
    """``<runtime dir>/<hash>.bench``: a symlink to the bench file, so that a command
    given a bus spec or a serial port (``bus dump``, ``scan``) can find the services
    that hold it without knowing their bench files (:func:`served_links`)."""
    return default_socket_path(bench_path)[:-len(".sock")] + ".bench"


def register(bench_path: Any) -> str:
    entry = _index_entry(bench_path)
    os.makedirs(os.path.dirname(entry), mode=0o700, exist_ok=True)
    try:
        os.unlink(entry)
    except FileNotFoundError:
        pass
    os.symlink(_real(bench_path), entry)
    return entry


def unregister(bench_path: Any) -> None:
    try:
        os.unlink(_index_entry(bench_path))
    except OSError:
        pass


def running_services() -> list:
    """Every live service of this user that registered itself (stale entries skipped)."""
    d = _runtime_dir()
    try:
        names = sorted(os.listdir(d))
    except OSError:
        return []
    out = []
    for name in names:
        if not name.endswith(".bench"):
            continue
        entry = os.path.join(d, name)
        try:
            target = os.readlink(entry)
        except OSError:
            continue
        if not os.path.exists(target):
            # A killed service of a bench file since removed (a test's temporary bench): its
            # entry and socket can never be found again; tidy them.
            for stale in (entry, entry[:-len(".bench")] + ".sock"):
                try:
                    os.unlink(stale)
                except OSError:
                    pass
            continue
        info = find_service(target)
        if info is not None:
            out.append(info)
    return out


def _same_link(a: str, b: str) -> bool:
    if a == b:
        return True
    try:
        return os.path.exists(a) and os.path.exists(b) and os.path.samefile(a, b)
    except OSError:
        return False


def served_link(link: str) -> Optional[ServiceInfo]:
    """The live service holding this bus spec or serial port (as its bench file names
    it, or the same device file), or None."""
    for info in running_services():
        if any(_same_link(str(held), link) for held in info.links):
            return info
    return None


def find_service(bench_path: Any) -> Optional[ServiceInfo]:
    """The running service of this bench file, or None: a live process holds the lock
    file's flock and the socket it names exists.  Reads only (a reader's test lock is
    shared and let go at once, so two readers never block each other)."""
    path = lock_path(bench_path)
    try:
        fd = os.open(path, os.O_RDONLY | os.O_CLOEXEC)
    except OSError:
        return None
    try:
        try:
            fcntl.flock(fd, fcntl.LOCK_SH | fcntl.LOCK_NB)
        except BlockingIOError:
            pass                        # held: a service runs
        except OSError as e:            # pragma: no cover - a filesystem without flock
            if e.errno not in (errno.ENOLCK, errno.EINVAL):
                raise
            return None
        else:
            fcntl.flock(fd, fcntl.LOCK_UN)   # nobody holds it: a stale file
            return None
        info = _read_info(fd)
    finally:
        os.close(fd)
    if info is None or not os.path.exists(info.socket):
        return None       # starting (faces not up yet) or broken: not a service to talk to
    return info

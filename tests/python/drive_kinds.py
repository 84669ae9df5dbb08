"""The kinds every Drive API test runs against, and the rig that serves each one's
simulator the way a bench is wired (shared by test_drive_api.py, its blocking face,
and test_aio_drive.py, the same cases awaited).

A per-kind table says only what differs in the *test bench* (address, how to
provoke a fault on the simulator, a parameter with a valid value); the scripts
themselves are the same for every kind.
"""
from __future__ import annotations

import itertools
import pathlib
from dataclasses import dataclass, field
from typing import Any, Callable

import pytest

import motorbus
from motorbus import Units
from motorbus.sim import SimBench

_names = itertools.count()


@dataclass
class Kind:
    kind: str
    address: str
    scale: float                      # user units (mm) per native unit
    fault: Callable[[Any, Any], None]  # (sim, drive): provokes a fault
    param: str                        # a writable parameter and a valid value for it
    value: Any
    jog: float                        # user units / s
    home: Any = None                  # home() method (None = the drive's default)
    setup: Callable[[Any], None] = lambda drive: None   # fast profile for the test
    unfault: Callable[[Any], None] = lambda sim: None   # removes the fault's cause (not its latch)
    open_options: dict = field(default_factory=dict)
    sim_options: dict = field(default_factory=dict)
    #: Where the simulator's shaft is, native units: read from the simulator itself, so a
    #: test sees the motor from outside the drive objects it commanded.
    shaft: Callable[[Any], float] = lambda sim: sim.position
    #: A target (user units) far enough that the simulator does not get there before a
    #: cancellation sent once the move runs lands, even on a loaded machine.
    far: float = 400.0


def _cia402_setup(drive: Any) -> None:
    drive.params["0x6081"] = 20000   # profile velocity, inc/s
    drive.params["0x6083"] = 400000
    drive.params["0x6084"] = 400000


def _arcus_setup(drive: Any) -> None:
    drive.params["HSPD"] = 20000     # pps (counts/s with StepNLoop)
    drive.params["LSPD"] = 2000      # HL homing searches at LSPD
    drive.params["ACC"] = 20         # ms


def _arcus_fault(sim: Any, drive: Any) -> None:
    sim.force_limit(-1, True)        # the -limit switch closes...
    drive.jog(-10.0)                 # ...and a jog into it latches a limit error


def _arcus_canopen_setup(drive: Any) -> None:
    drive.params["0x6081"] = 20000   # profile velocity, counts/s (StepNLoop on)
    drive.params["0x6083"] = 20      # ms (manual 000: accelerations are times)
    drive.params["0x6084"] = 20
    drive.params["0x6099:01"] = 20000  # home switch speed
    drive.params["0x6099:02"] = 2000   # zero position speed
    drive.params["0x609A"] = 20
def _pmc007_setup(drive: Any) -> None:
    drive.params["maximum_speed"] = 20000   # 6003h, pps: the run speed of position moves


def _dmac_setup(drive: Any) -> None:
    drive.params["#LOW_SPEED"] = 60000   # 0.01 rpm: the reference search speed


KINDS = {
    "dmac": Kind("dmac", "00", 0.01, fault=lambda sim, drive: sim.set_supply_voltage(11000),  # undervoltage
                 unfault=lambda sim: sim.set_supply_voltage(32000), param="#HIGH_SPEED", value=50000, jog=50.0,
                 home="reference", setup=_dmac_setup, sim_options={"reference_switch": 3000},
                 shaft=lambda sim: sim.state().position),
    "arcus": Kind("arcus", "01", 0.01, fault=_arcus_fault, unfault=lambda sim: sim.force_limit(-1, None),
                  param="HSPD", value=15000, jog=50.0, home="HL+", setup=_arcus_setup,
                  shaft=lambda sim: sim.pulse_position),
    "cia402": Kind("cia402", "5", 0.01, fault=lambda sim, drive: sim.inject_fault(0x5441),
                   param="0x6081", value=25000, jog=50.0, home=19, setup=_cia402_setup),
    "arcus-canopen": Kind("arcus-canopen", "1", 0.01, fault=_arcus_fault, unfault=lambda sim: sim.force_limit(-1, None),
                          param="0x2004:02", value=1200, jog=50.0, home=19, setup=_arcus_canopen_setup,
                          shaft=lambda sim: sim.pulse_position),
    "unitek": Kind("unitek", "0x201", 0.01, fault=lambda sim, drive: sim.set_hardware_enable(False),
                   unfault=lambda sim: sim.set_hardware_enable(True), param="ACC_RAMP", value=200, jog=50.0,
                   setup=lambda drive: drive.params.__setitem__("ACC_RAMP", 20),  # ms to N max
                   # a short deceleration ramp (speed 0 is the stop): a stop lands well short of a far target
                   sim_options={"calibrated": True, "dec_ramp_ms": 20}, shaft=lambda sim: sim.position_num,
                   far=4000.0),   # fast: 400 mm came to its end before a cancellation on a loaded CI run
    "pmc007": Kind("pmc007", "5", 0.01, fault=lambda sim, drive: sim.inject_error(1),  # UVLO
                   param="start_speed", value=500, jog=50.0, home="ext1", setup=_pmc007_setup),
    # The out-of-tree test kind (tests/plugin_kind/): registered only while its package is on the path.
    "toy": Kind("toy", "1", 0.01, fault=lambda sim, drive: sim.set_fault_input(True),
                unfault=lambda sim: sim.set_fault_input(False), param="SPEED", value=6000, jog=50.0, home="here",
                setup=lambda drive: drive.params.__setitem__("SPEED", 20000)),
}
#: Where the out-of-tree kinds' packages are (their entry points come with them).
OUT_OF_TREE = {"toy": pathlib.Path(__file__).resolve().parents[1] / "plugin_kind" / "python"}


@pytest.fixture(params=sorted(KINDS))
def kind(request) -> Kind:
    if request.param in OUT_OF_TREE:
        if not hasattr(motorbus._core, "toy"):
            pytest.skip("built without MOTORBUS_TESTS (the out-of-tree test kind's C++ is not in _core)")
        monkeypatch = request.getfixturevalue("monkeypatch")
        monkeypatch.syspath_prepend(str(OUT_OF_TREE[request.param]))
        monkeypatch.setattr(motorbus.registry, "_cache", {})   # read the entry points again, with the package's
    return KINDS[request.param]


@dataclass
class Rig:
    drive: Any
    sim: Any
    reopen: Callable[[], Any]   # another Drive object on the same simulated drive


@pytest.fixture(params=["transport", "in_process"])
def rig(request, kind):
    """A Drive and its simulator on the chosen link; everything closed afterwards."""
    spec = f"{kind.kind}:{kind.address}"
    plugin = motorbus.registry.drive_plugin(kind.kind)
    units = Units("mm", kind.scale)
    opened: list = []

    def opener(**where):
        def open_one():
            d = motorbus.open_drive(kind.kind, address=kind.address, units=units, **where, **kind.open_options)
            opened.append(d)
            return d
        return open_one

    if plugin.transport == "serial":
        with SimBench([spec], sim_options={kind.kind: kind.sim_options}) as bench:
            reopen = opener(line=bench.lines[0].pty_path)
            yield Rig(reopen(), bench.sims[(kind.kind, plugin.check_address(kind.address))], reopen)
            for d in opened:
                d.close()
        return
    name = f"virtual:drive-api-{next(_names)}"
    if request.param == "transport":
        with SimBench([spec], bus=name, sim_options={kind.kind: kind.sim_options}) as bench:
            srv = bench.can.servers[0]
            reopen = opener(bus=f"socketcand:{srv.host}:{srv.port}/can0")
            yield Rig(reopen(), bench.sims[(kind.kind, kind.address)], reopen)
            for d in opened:
                d.close()
    else:
        with motorbus.open_bus(name) as sim_bus:
            sim = plugin.make_sim(kind.address, bus=sim_bus, **kind.sim_options)
            reopen = opener(bus=name)
            yield Rig(reopen(), sim, reopen)
            for d in opened:
                d.close()
            sim.close()

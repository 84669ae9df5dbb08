"""Configuration shared by the interop tests.

Channel Access: libca reads the EPICS environment once per process, when its first
context is made, and a test module importing pyepics, aioca or ophyd can come first in a
worker; so this worker's loopback CA environment (its own port, no broadcast, beacons to
127.0.0.1) is set here, at import, before any test module loads a client (ca_env.py).
"""
import ca_env

ca_env.configure()

"""Drive._open_on, the one place every kind's ``open`` leaves the link it was given:
a bus named by a spec is opened for the drive and closed with it, or at once when the
open fails; a Bus the caller passed is never closed by a failed open."""
import pytest

import motorbus
from motorbus import bus as bus_module
from motorbus import registry

CAN_KINDS = ["cia402", "arcus-canopen", "pmc007", "unitek"]


@pytest.fixture
def served(request):
    """A simulated drive of the kind on a virtual bus of its own; yields (kind class, spec, hub)."""
    cls = registry.drive_plugin(request.param)
    spec = f"virtual:open-on-{request.param}"
    hub = motorbus.open_bus(spec)
    sim = cls.make_sim(cls.default_address)
    sim.attach(hub)
    yield cls, spec, hub
    sim.close()
    hub.close()


@pytest.fixture
def opened_buses(monkeypatch):
    """Every bus open_bus opens during the test."""
    buses = []
    real = bus_module.open_bus

    def recording(spec, **options):
        buses.append(real(spec, **options))
        return buses[-1]

    monkeypatch.setattr(bus_module, "open_bus", recording)
    return buses


@pytest.mark.parametrize("served", CAN_KINDS, indirect=True)
def test_a_failed_open_closes_the_bus_it_opened_and_only_that(served, opened_buses):
    cls, spec, hub = served
    # The Drive refuses units that are not a Units after the client is built on the bus.
    with pytest.raises(motorbus.InvalidArgument, match="units: a motorbus.Units, not str"):
        motorbus.open_drive(cls.kind, bus=spec, address=cls.default_address, units="mm")
    assert len(opened_buses) == 1 and opened_buses[0].closed
    with pytest.raises(motorbus.InvalidArgument, match="units: a motorbus.Units, not str"):
        cls.open(bus=hub, address=cls.default_address, units="mm")
    assert not hub.closed

    drive = motorbus.open_drive(cls.kind, bus=spec, address=cls.default_address)
    assert len(opened_buses) == 2 and not opened_buses[1].closed
    drive.position      # the drive answers through the bus it opened
    drive.close()
    assert opened_buses[1].closed and not hub.closed


@pytest.mark.parametrize("kind, transport", [("cia402", "CAN"), ("unitek", "CAN"), ("arcus", "serial"),
                                             ("dmac", "serial")])
def test_open_refuses_the_other_transport_s_link_naming_the_kind(kind, transport, opened_buses):
    cls = registry.drive_plugin(kind)
    wrong = {"line": "/dev/null"} if transport == "CAN" else {"bus": "virtual:open-on-wrong"}
    with pytest.raises(motorbus.InvalidArgument, match=f"^{kind}: a {transport} drive takes"):
        cls.open(address=cls.default_address, **wrong)
    assert opened_buses == []

"""pytest fixtures for simulated sensors (installed as a pytest11 plugin).

    def test_machine(sensor_bus):
        bus = sensor_bus(["dst-x730-xy30@0x20"])       # started, stopped after the test
        bus.set(0x20, x=10)

Options: ``--sensor-interface`` (default vcan0, or $CANOPEN_SENSOR_IFACE),
``--sensor-seed`` (default 1). The program: $CANOPEN_SENSOR, PATH, or the
checkout's build/bin (canopen_sensor_sim.find_program).
"""
import os

import pytest

from canopen_sensor_sim import SimBus


def pytest_addoption(parser):
    group = parser.getgroup("canopen-sensor-sim")
    group.addoption("--sensor-interface", default=os.environ.get("CANOPEN_SENSOR_IFACE", "vcan0"),
                    help="CAN interface of the simulated sensors (default vcan0)")
    group.addoption("--sensor-seed", type=int, default=1,
                    help="seed of the sensors' motion generator (default 1)")


@pytest.fixture
def sensor_interface(request):
    """The CAN interface the simulated sensors use."""
    return request.config.getoption("--sensor-interface")


@pytest.fixture
def sensor_bus(request, tmp_path):
    """A factory: sensor_bus(nodes, **kwargs) starts a SimBus (nodes as
    ``"PRODUCT[@NODEID][/IFACE]"``), stored sets in the test's tmp_path;
    every bus it started is stopped after the test."""
    buses = []

    def start(nodes, **kwargs):
        kwargs.setdefault("interface", request.config.getoption("--sensor-interface"))
        kwargs.setdefault("seed", request.config.getoption("--sensor-seed"))
        kwargs.setdefault("nvm_dir", tmp_path / f"nvm{len(buses)}")
        bus = SimBus(nodes, **kwargs)
        buses.append(bus)
        return bus.start()

    yield start
    for bus in buses:
        bus.close()

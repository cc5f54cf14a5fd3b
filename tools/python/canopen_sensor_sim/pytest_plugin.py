"""pytest fixtures for simulated sensors (installed as a pytest11 plugin).

    def test_machine(sensor_bus):
        bus = sensor_bus(["dst-x730-xy30@0x20"])       # started, stopped after the test
        bus.set(0x20, x=10)

Options: ``--sensor-interface`` (default $CANOPEN_SENSOR_IFACE, else vcan0
where it exists, else python-can's udp_multicast bus on the loopback),
``--sensor-seed`` (default 1). The program: $CANOPEN_SENSOR, PATH, or the
checkout's build/bin (canopen_sensor_sim.find_program).
"""
import os

import pytest

from canopen_sensor_sim import SimBus, default_interface, python_can_args


def pytest_addoption(parser):
    group = parser.getgroup("canopen-sensor-sim")
    group.addoption("--sensor-interface", default=os.environ.get("CANOPEN_SENSOR_IFACE"),
                    help="CAN interface of the simulated sensors, or udp_multicast:GROUP[:PORT]"
                         "[%%IFNAME] (default vcan0 where it exists, else "
                         "udp_multicast:239.74.163.2:43113%%lo)")
    group.addoption("--sensor-seed", type=int, default=1,
                    help="seed of the sensors' motion generator (default 1)")


@pytest.fixture
def sensor_interface(request):
    """The CAN interface the simulated sensors use."""
    return request.config.getoption("--sensor-interface") or default_interface()


@pytest.fixture
def sensor_can_args(sensor_interface):
    """``can.Bus`` / ``canopen.Network.connect`` arguments for the master
    on the sensors' bus: ``net.connect(**sensor_can_args)``."""
    return python_can_args(sensor_interface)


@pytest.fixture
def sensor_bus(request, tmp_path):
    """A factory: sensor_bus(nodes, **kwargs) starts a SimBus (nodes as
    ``"PRODUCT[@NODEID][/IFACE]"``), stored sets in the test's tmp_path;
    every bus it started is stopped after the test."""
    buses = []

    def start(nodes, **kwargs):
        kwargs.setdefault("interface", request.getfixturevalue("sensor_interface"))
        kwargs.setdefault("seed", request.config.getoption("--sensor-seed"))
        kwargs.setdefault("nvm_dir", tmp_path / f"nvm{len(buses)}")
        bus = SimBus(nodes, **kwargs)
        buses.append(bus)
        return bus.start()

    yield start
    for bus in buses:
        bus.close()

"""A simulator host and a ROS host (two network namespaces and a veth, ``netns.py``); the link
goes down for 10 s and comes back: bridging resumes by itself and nothing is duplicated.

* ZeroMQ: the simulator host is the real Fortress C++ peer (a Clock publisher stamping every
  message with its send time, a typed Twist subscriber); the ROS host runs the bridge with
  ``GZ_RELAY`` pointing at the simulator host. The hosts use different discovery groups, so
  discovery crosses only as relayed unicast (docs/protocol-zmq-discovery.md §2.7).
* Zenoh: a Zenoh router on the simulator host, our ZenohGzNode there as the Gazebo side (no
  Jetty binary exists here), the bridge on the ROS host as a client of the router.

The ROS side is an rclpy probe on the ROS host (``ros_probe.py``). The outage is longer than
discovery's silence interval (3 s) and Zenoh's default lease (10 s): each side forgets the
other and must find it again.
"""

from __future__ import annotations

import json
import os
import re
import sys
import time
from collections.abc import Callable, Iterator
from pathlib import Path

import pytest

from ros_gz_bridge_py.msgs import message_class
from testing.e2e_harness import PARAMETER_BRIDGE, ProcessGroup
from testing.gzpeer import PeerProcess, peer_binary, require_peer
from tests.faults.netns import TwoHosts, require_namespaces, two_hosts

pytestmark = [pytest.mark.peer, pytest.mark.ros, pytest.mark.slow]

HERE = Path(__file__).resolve().parent
PROBE = HERE / "ros_probe.py"
GZ_SIDE = HERE / "gz_side.py"
ROUTER = HERE.parent / "bridge" / "e2e_zenoh_router.py"
#: How long the link is down.
OUTAGE = 10.0
#: How long bridging may take to start, and to resume after the link is back.
SETTLE = 30.0
LIFETIME = "150"
CLOCK, CMD = "/clock", "/cmd_vel"
BRIDGE_ARGS = (
    f"{CLOCK}@rosgraph_msgs/msg/Clock[gz.msgs.Clock",
    f"{CMD}@geometry_msgs/msg/Twist]gz.msgs.Twist",
)


def lines(process: PeerProcess, prefix: str) -> list[str]:
    return [
        line[len(prefix) :] for line in process.output().splitlines() if line.startswith(prefix)
    ]


def wait_for(
    what: str, condition: Callable[[], bool], timeout: float, *processes: PeerProcess
) -> None:
    deadline = time.monotonic() + timeout
    while not condition():
        if time.monotonic() > deadline:
            outputs = "\n".join(f"--- {p.args!r}\n{p.output()[-3000:]}" for p in processes)
            pytest.fail(f"{what} within {timeout:g} s; outputs:\n{outputs}")
        time.sleep(0.1)


@pytest.fixture
def hosts() -> Iterator[TwoHosts]:
    require_namespaces()
    with two_hosts(f"{os.getpid() % 100000}") as made:
        yield made


@pytest.fixture
def group() -> Iterator[ProcessGroup]:
    processes = ProcessGroup()
    yield processes
    processes.stop()


def survive_an_outage(
    hosts: TwoHosts, probe: PeerProcess, gazebo_cmd: Callable[[], list[str]], *others: PeerProcess
) -> None:
    """Bridging works, the link goes down for OUTAGE, comes back, and bridging works again;
    every clock stamp reaches ROS at most once and every command reaches Gazebo at most once."""
    watched = (probe, *others)
    wait_for("clocks on the ROS host", lambda: len(lines(probe, "CLOCK ")) >= 10, SETTLE, *watched)
    wait_for("commands on the simulator host", lambda: len(gazebo_cmd()) >= 10, SETTLE, *watched)
    hosts.ros.set_link(up=False)
    time.sleep(OUTAGE)
    clocks_at_up, commands_at_up = len(lines(probe, "CLOCK ")), len(gazebo_cmd())
    hosts.ros.set_link(up=True)
    wait_for(
        "clocks again after the outage",
        lambda: len(lines(probe, "CLOCK ")) >= clocks_at_up + 20,
        SETTLE,
        *watched,
    )
    wait_for(
        "commands again after the outage",
        lambda: len(gazebo_cmd()) >= commands_at_up + 20,
        SETTLE,
        *watched,
    )
    clocks = lines(probe, "CLOCK ")
    commands = gazebo_cmd()
    assert len(clocks) == len(set(clocks)), "a clock message reached ROS twice"
    assert len(commands) == len(set(commands)), "a command reached Gazebo twice"


def test_zeromq_relay_bridging_survives_a_link_outage(
    hosts: TwoHosts, group: ProcessGroup, tmp_path: Path
) -> None:
    require_peer()
    partition = f"two-hosts-{os.getpid()}"
    sim_env = hosts.sim.gazebo_env(partition)
    ros_env = hosts.ros.gazebo_env(partition, relay=hosts.sim.address)
    clock_file = tmp_path / "clock.pb"
    clock_file.write_bytes(message_class("gz.msgs.Clock")().SerializeToString())
    peer = str(peer_binary())
    clock_args = ["kind-pub", CLOCK, "ignition.msgs.Clock", str(clock_file), LIFETIME]
    clock_args += ["--stamp", "sim", "--hz", "20", "--wait", "60"]
    clock = group.start(hosts.sim.command([peer, *clock_args]), sim_env)
    echo = group.start(
        hosts.sim.command([peer, "echo", CMD, "ignition.msgs.Twist", LIFETIME]), sim_env
    )
    bridge = group.start(hosts.ros.command([str(PARAMETER_BRIDGE), *BRIDGE_ARGS]), ros_env)
    probe = group.start(
        hosts.ros.command([sys.executable, str(PROBE), CLOCK, CMD, LIFETIME]), ros_env
    )
    survive_an_outage(
        hosts,
        probe,
        lambda: re.findall(r"^MSG \S+ (linear .*)$", echo.output(), re.MULTILINE),
        bridge,
        echo,
        clock,
    )


def _zenoh_env(hosts: TwoHosts, host_env: dict[str, str], mode: str, port: int) -> dict[str, str]:
    overrides = {
        "mode": json.dumps(mode),
        "scouting/multicast/enabled": "false",
        "scouting/gossip/enabled": "false",
        "listen/endpoints": "[]",
        "connect/endpoints": json.dumps([f"tcp/{hosts.sim.address}:{port}"]),
    }
    return dict(
        host_env,
        GZ_TRANSPORT_IMPLEMENTATION="zenoh",
        GZ_TRANSPORT_ZENOH_CONFIG_OVERRIDE=";".join(f"{k}={v}" for k, v in overrides.items()),
    )


def test_zenoh_router_bridging_survives_a_link_outage(hosts: TwoHosts, group: ProcessGroup) -> None:
    partition = f"two-hosts-z-{os.getpid()}"
    port = 7447
    router = group.start(
        hosts.sim.command([sys.executable, str(ROUTER), str(port), LIFETIME, hosts.sim.address])
    )
    wait_for("the router", lambda: "READY" in router.output(), SETTLE, router)
    sim_env = _zenoh_env(hosts, hosts.sim.gazebo_env(partition), "peer", port)
    ros_env = _zenoh_env(hosts, hosts.ros.gazebo_env(partition), "client", port)
    gazebo = group.start(
        hosts.sim.command([sys.executable, str(GZ_SIDE), CLOCK, CMD, LIFETIME]), sim_env
    )
    bridge = group.start(hosts.ros.command([str(PARAMETER_BRIDGE), *BRIDGE_ARGS]), ros_env)
    probe = group.start(
        hosts.ros.command([sys.executable, str(PROBE), CLOCK, CMD, LIFETIME]), ros_env
    )
    survive_an_outage(hosts, probe, lambda: lines(gazebo, "MSG "), bridge, gazebo, router)

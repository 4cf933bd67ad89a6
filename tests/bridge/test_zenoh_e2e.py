"""The TurtleBot3 configuration bridges every entry over Zenoh (gz-transport 15), end to end.

There is no Jetty binary here, so the Gazebo side is our ``ZenohGzNode`` in a process of its own
(``e2e_zenoh_gazebo.py``) publishing the Gazebo->ROS entries and echoing ``cmd_vel``. The
bridge is the real ``parameter_bridge`` with ``GZ_TRANSPORT_IMPLEMENTATION=zenoh`` and its
Zenoh configuration in ``GZ_TRANSPORT_ZENOH_CONFIG_OVERRIDE``, gz-transport's own variable:
explicit ``tcp/127.0.0.1`` endpoints, no scouting. Peer mode (the bridge listens, Gazebo
connects) and client mode (both connect to a router process).
"""

from __future__ import annotations

import functools
import json
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path

import pytest

from testing.e2e_harness import (
    RUN_TIMEOUT,
    ConfigEntry,
    GzEcho,
    ProcessGroup,
    RosChecker,
    lines,
    parse_gz,
    read_entries,
    wait_all,
)
from testing.gzpeer import PeerProcess, wait_for_line
from testing.loopback import free_port, zenoh_env
from tests.bridge.e2e_values import TWIST_TO_GZ, mismatches, sample_for

pytestmark = [pytest.mark.ros]

CONFIG = Path("/work/shared/data/configs/turtlebot3_waffle_bridge.yaml")
HERE = Path(__file__).resolve().parent
GAZEBO_SIDE = HERE / "e2e_zenoh_gazebo.py"
ROUTER = HERE / "e2e_zenoh_router.py"
ENTRIES = read_entries(CONFIG)


@dataclass
class ZenohRun:
    bridge: PeerProcess
    checker: RosChecker
    cmd_vel: GzEcho


def start_zenoh_run(group: ProcessGroup, mode: str) -> ZenohRun:
    """Bridge, Gazebo side and ROS checker wired through Zenoh in ``mode`` (peer or client)."""
    port = free_port()
    endpoint = f"tcp/127.0.0.1:{port}"
    if mode == "peer":
        bridge_env = zenoh_env("peer", listen=[endpoint], connect=[])
        gazebo_env = zenoh_env("peer", listen=[], connect=[endpoint])
    else:
        router = group.python(ROUTER, str(port), str(RUN_TIMEOUT + 30))
        wait_for_line(router, "^READY$", timeout=15)
        bridge_env = gazebo_env = zenoh_env("client", listen=[], connect=[endpoint])
    bridge = group.bridge("--ros-args", "-p", f"config_file:={CONFIG}", env=bridge_env)
    gz_to_ros = [entry for entry in ENTRIES if entry.direction == "GZ_TO_ROS"]
    ros_to_gz = [entry for entry in ENTRIES if entry.direction == "ROS_TO_GZ"]
    spec = {
        "publish": [
            [e.gz_topic, e.gz_type, sample_for(e.gz_type, e.gz_topic).harmonic_text]
            for e in gz_to_ros
        ],
        "echo": [[e.gz_topic, e.gz_type] for e in ros_to_gz],
        "seconds": RUN_TIMEOUT + 30,
    }
    gazebo = group.python(GAZEBO_SIDE, json.dumps(spec), env=gazebo_env)
    (cmd_vel,) = ros_to_gz
    checker = RosChecker(
        group,
        [(e.ros_topic, e.ros_type) for e in gz_to_ros],
        [(cmd_vel.ros_topic, cmd_vel.ros_type, TWIST_TO_GZ.values)],
    )
    run = ZenohRun(bridge, checker, GzEcho(gazebo, TWIST_TO_GZ.gz_type_name))
    checks: dict[str, Callable[[], bool]] = {
        e.ros_topic: functools.partial(_arrived_in_ros, run, e) for e in gz_to_ros
    }
    checks[cmd_vel.ros_topic] = lambda: _expected_twist() in run.cmd_vel.messages()
    wait_all(checks, RUN_TIMEOUT)
    return run


def _arrived_in_ros(run: ZenohRun, entry: ConfigEntry) -> bool:
    expected = sample_for(entry.gz_type, entry.gz_topic).ros
    return any(not mismatches(expected, msg) for msg in run.checker.messages(entry.ros_topic))


def _expected_twist() -> object:
    return parse_gz(TWIST_TO_GZ.gz_type_name, TWIST_TO_GZ.gz_text)


class ZenohE2E:
    """Every TurtleBot3 entry over Zenoh in ``MODE``; one run for the class."""

    MODE = ""

    @pytest.fixture(scope="class")
    @classmethod
    def run(cls) -> Iterator[ZenohRun]:
        group = ProcessGroup()
        try:
            yield start_zenoh_run(group, cls.MODE)
        finally:
            group.stop()

    @pytest.mark.parametrize(
        "entry",
        [e for e in ENTRIES if e.direction == "GZ_TO_ROS"],
        ids=lambda e: e.ros_topic,
    )
    def test_gazebo_to_ros_entry_arrives_converted(self, run: ZenohRun, entry: ConfigEntry) -> None:
        arrived = run.checker.messages(entry.ros_topic)
        assert arrived, f"nothing arrived on {entry.ros_topic}; bridge:\n{run.bridge.output()}"
        expected = sample_for(entry.gz_type, entry.gz_topic).ros
        problems = [mismatches(expected, msg) for msg in arrived]
        assert any(not found for found in problems), f"{entry.ros_topic}: {problems}"

    def test_gazebo_side_speaks_zenoh(self, run: ZenohRun) -> None:
        # Data that reached a Zenoh-only peer proves the bridge used Zenoh too.
        assert lines(run.cmd_vel.proc, "NODE ") == ["ZenohGzNode"]

    def test_cmd_vel_arrives_in_gazebo_converted(self, run: ZenohRun) -> None:
        arrived = run.cmd_vel.messages()
        assert _expected_twist() in arrived, (
            f"cmd_vel: got {arrived[:3]}; bridge:\n{run.bridge.output()}\n"
            f"gazebo side:\n{run.cmd_vel.proc.output()}"
        )


class TestZenohPeerMode(ZenohE2E):
    MODE = "peer"


class TestZenohClientModeThroughRouter(ZenohE2E):
    MODE = "client"

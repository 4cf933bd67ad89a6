"""The real user configurations bridge every entry, end to end, with real processes.

For each YAML file of ``shared/data/configs`` (used unchanged) and each Gazebo line:
``parameter_bridge --ros-args -p config_file:=<file>``, one C++ ign-transport 11 peer per
Gazebo->ROS entry, an rclpy checker that subscribes to every ROS topic and publishes the
ROS->Gazebo entry, and a typed C++ echo of that entry. As Harmonic, the peers put ``gz.msgs.*``
names and Harmonic layouts on the wire (``--wire-type``, see ``testing/peer``); as Fortress, they
are what they are: ``ignition.msgs.*`` publishers and typed ``ignition.msgs.*`` subscribers
(as the DiffDrive system is), with the Fortress IMU layout. Each arrival is checked field by
field against ``e2e_values`` (the rules of docs/conversions.md), and traffic against the configured
direction must not cross.
"""

from __future__ import annotations

import os
import time
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import pytest

from ros_gz_bridge_py.msgs.names import Spelling, respell
from testing.e2e_harness import (
    RUN_TIMEOUT,
    ConfigEntry,
    GzEcho,
    ProcessGroup,
    RosChecker,
    parse_gz,
    read_entries,
    status_rows,
    wait_all,
)
from testing.gzpeer import PeerProcess
from tests.bridge.e2e_values import (
    CLOCK_FROM_ROS,
    IMU_FORTRESS,
    TWIST_FROM_GZ_NOT_BRIDGED,
    TWIST_TO_GZ,
    GzSample,
    mismatches,
    sample_for,
)

pytestmark = [pytest.mark.peer, pytest.mark.ros, pytest.mark.slow]

CONFIG_DIR = Path("/work/shared/data/configs")
ROS_SAMPLES = {"gz.msgs.Twist": TWIST_TO_GZ}
#: How long reverse-direction publishers keep going after everything expected arrived.
REVERSE_DWELL = 2.0
#: The Gazebo lines the peers play.
HARMONIC = "harmonic"
FORTRESS = "fortress"


def line_sample(line: str, entry: ConfigEntry) -> GzSample:
    """What a simulator of ``line`` publishes for ``entry`` (Fortress: its own IMU layout)."""
    if line == FORTRESS and entry.gz_type == "gz.msgs.IMU":
        return IMU_FORTRESS
    return sample_for(entry.gz_type, entry.gz_topic)


def line_type(line: str, gz_type: str) -> str:
    """The type name a process of ``line`` uses for ``gz_type``."""
    return respell(gz_type, Spelling.IGNITION) if line == FORTRESS else gz_type


@dataclass
class ConfigRun:
    """One bridge on one configuration file, with everything that arrived."""

    path: Path
    line: str
    entries: list[ConfigEntry]
    group: ProcessGroup
    checker: RosChecker
    #: Echo of every ROS->Gazebo entry's gz topic, and of the clock topic (reverse check).
    echoes: dict[str, GzEcho]
    bridge: PeerProcess


def _gz_sample(entry: ConfigEntry) -> Any:
    sample = ROS_SAMPLES[entry.gz_type]
    return parse_gz(sample.gz_type_name, sample.gz_text)


def _ros_arrived(checker: RosChecker, line: str, entry: ConfigEntry) -> bool:
    expected = line_sample(line, entry).ros
    return any(not mismatches(expected, msg) for msg in checker.messages(entry.ros_topic))


def start_config_run(name: str, line: str, *, native: bool = True) -> ConfigRun:
    """The bridge with Gazebo publishers, echoes and a ROS checker, after the Gazebo->ROS phase.

    ROS publishers of the ROS->Gazebo entries start later, in their own test, so a bridge that
    fails on them cannot take the Gazebo->ROS results down with it. ``native`` False runs the
    bridge with ``ROS_GZ_BRIDGE_NATIVE=off`` (the Python path; docs/native.md §1).
    """
    path = CONFIG_DIR / name
    entries = read_entries(path)
    group = ProcessGroup()
    try:
        env = None if native else {**os.environ, "ROS_GZ_BRIDGE_NATIVE": "off"}
        bridge = group.bridge("--ros-args", "-p", f"config_file:={path}", env=env)
        echoes: dict[str, GzEcho] = {}
        reverse: list[tuple[str, str, dict[str, Any]]] = []
        # Harmonic names go on the wire with --wire-type; Fortress peers need none.
        wire_type = (lambda gz_type: gz_type) if line == HARMONIC else (lambda _: None)
        for entry in entries:
            if entry.direction == "GZ_TO_ROS":
                sample = line_sample(line, entry)
                group.peer(*sample.peer_pub_args(entry.gz_topic, wire_type(entry.gz_type)))
            if entry.direction == "ROS_TO_GZ":
                type_name = ROS_SAMPLES[entry.gz_type].gz_type_name
                echoes[entry.gz_topic] = GzEcho.peer(
                    group, entry.gz_topic, type_name, line_type(line, entry.gz_type)
                )
                # Against the direction: a Gazebo publisher on the same topic.
                group.peer(
                    *TWIST_FROM_GZ_NOT_BRIDGED.peer_pub_args(
                        entry.gz_topic, wire_type(entry.gz_type)
                    )
                )
            if entry.gz_type == "gz.msgs.Clock":
                echoes[entry.gz_topic] = GzEcho.peer(
                    group, entry.gz_topic, "Clock", line_type(line, entry.gz_type)
                )
                reverse.append((entry.ros_topic, entry.ros_type, CLOCK_FROM_ROS))
        checker = RosChecker(
            group, [(entry.ros_topic, entry.ros_type) for entry in entries], reverse
        )
        checks = {
            entry.ros_topic: lambda e=entry: _ros_arrived(checker, line, e)
            for entry in entries
            if entry.direction == "GZ_TO_ROS"
        }
        wait_all(checks, RUN_TIMEOUT)
        time.sleep(REVERSE_DWELL)
    except BaseException:
        group.stop()
        raise
    return ConfigRun(path, line, entries, group, checker, echoes, bridge)


#: The configuration entries each test method runs for, by direction.
ENTRY_DIRECTIONS = {
    "test_gazebo_to_ros_entry_arrives_converted": "GZ_TO_ROS",
    "test_ros_to_gazebo_entry_arrives_converted": "ROS_TO_GZ",
}


def pytest_generate_tests(metafunc: pytest.Metafunc) -> None:
    """``entry``: each entry of the class's configuration in the test's direction."""
    if "entry" in metafunc.fixturenames and metafunc.cls is not None:
        direction = ENTRY_DIRECTIONS[metafunc.function.__name__]
        entries = [
            entry
            for entry in read_entries(CONFIG_DIR / metafunc.cls.CONFIG)
            if entry.direction == direction
        ]
        metafunc.parametrize("entry", entries, ids=[entry.ros_topic for entry in entries])


class ConfigE2E:
    """The end-to-end tests of one configuration file (``CONFIG``) against peers of one Gazebo
    line (``LINE``); one run for the class."""

    CONFIG = ""
    LINE = HARMONIC
    #: The native data plane where the extension is built (False: the Python path).
    NATIVE = True

    @pytest.fixture(scope="class")
    @classmethod
    def run(cls) -> Iterator[ConfigRun]:
        started = start_config_run(cls.CONFIG, cls.LINE, native=cls.NATIVE)
        yield started
        started.group.stop()

    def test_gazebo_to_ros_entry_arrives_converted(
        self, run: ConfigRun, entry: ConfigEntry
    ) -> None:
        expected = line_sample(run.line, entry).ros
        arrived = run.checker.messages(entry.ros_topic)
        assert arrived, f"nothing arrived on {entry.ros_topic}; bridge output:\n" + (
            run.bridge.output()
        )
        problems = [mismatches(expected, msg) for msg in arrived]
        assert any(not found for found in problems), f"{entry.ros_topic}: {problems}"

    def test_nothing_crosses_against_the_configured_direction(self, run: ConfigRun) -> None:
        for entry in run.entries:
            if entry.gz_type == "gz.msgs.Clock":
                seen = run.echoes[entry.gz_topic].messages()
                assert any(msg.sim.sec == 1234 for msg in seen), "the clock echo saw nothing"
                from_ros = [msg for msg in seen if msg.sim.sec == CLOCK_FROM_ROS["clock"]["sec"]]
                assert not from_ros, f"{entry.ros_topic} went ROS->Gazebo: {entry.direction}"
            if entry.direction == "ROS_TO_GZ":
                gz_side = run.echoes[entry.gz_topic].messages()
                assert any(msg.linear.x == -9.5 for msg in gz_side), "reverse publisher idle"
                crossed = [
                    msg
                    for msg in run.checker.messages(entry.ros_topic)
                    if not mismatches(TWIST_FROM_GZ_NOT_BRIDGED.ros, msg)
                ]
                assert not crossed, f"{entry.gz_topic} went Gazebo->ROS: {entry.direction}"

    def test_ros_to_gazebo_entry_arrives_converted(
        self, run: ConfigRun, entry: ConfigEntry
    ) -> None:
        sample = ROS_SAMPLES[entry.gz_type]
        publisher = RosChecker(run.group, [], [(entry.ros_topic, entry.ros_type, sample.values)])
        echo = run.echoes[entry.gz_topic]
        expected = _gz_sample(entry)
        # Both waited for: the publisher's MATCHED line may be read after the echo's message,
        # each process's output being collected by a thread of its own.
        wait_all(
            {
                "arrived": lambda: expected in echo.messages(),
                "matched": lambda: publisher.matched(entry.ros_topic),
            },
            RUN_TIMEOUT,
        )
        assert publisher.matched(entry.ros_topic), (
            f"the bridge never subscribed to {entry.ros_topic} in ROS within {RUN_TIMEOUT:g} s "
            f"(bridge exit status {run.bridge.returncode}); its status rows:\n"
            + "\n".join(status_rows(run.bridge, [entry.ros_topic]))
            + f"\nthe ROS publisher's output:\n{publisher.proc.output()}"
            + f"\nthe bridge's output:\n{run.bridge.output()}"
        )
        arrived = [msg for msg in echo.messages() if msg.linear.x != -9.5]
        assert expected in arrived, (
            f"{entry.gz_topic}: expected {expected}, got {arrived[:3]}; bridge output:\n"
            + run.bridge.output()
        )


class TestTurtlebot3Waffle(ConfigE2E):
    CONFIG = "turtlebot3_waffle_bridge.yaml"


class TestTurtlebot3WaffleOnFortress(ConfigE2E):
    """The TurtleBot3 migration tutorial's pairing: this file, unchanged, on Fortress."""

    CONFIG = "turtlebot3_waffle_bridge.yaml"
    LINE = FORTRESS


class TestTurtlebot3WaffleOnFortressPythonPath(ConfigE2E):
    """The same on the Python path (``ROS_GZ_BRIDGE_NATIVE=off``), the reference of the
    native one."""

    CONFIG = "turtlebot3_waffle_bridge.yaml"
    LINE = FORTRESS
    NATIVE = False


class TestTurtlebot3WafflePythonPath(ConfigE2E):
    CONFIG = "turtlebot3_waffle_bridge.yaml"
    NATIVE = False


class TestDiffCar(ConfigE2E):
    CONFIG = "diff_car_bridge.yaml"


class TestDiffCarOnFortress(ConfigE2E):
    CONFIG = "diff_car_bridge.yaml"
    LINE = FORTRESS

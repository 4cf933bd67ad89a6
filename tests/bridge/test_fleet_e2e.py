"""A fleet of ten robots in one bridge process, with ``config/fleet_bridge.yaml`` (issue 28).

One C++ ign-transport 11 peer plays the simulator (mode ``pub-fleet``: one node publishing
``/clock`` and every robot's odom, imu and joint_states, and subscribing to every robot's
``cmd_vel``, see ``testing/fleet_sim.py``); one ``parameter_bridge`` with the example file and
``robot=robot_1,...,robot_10``; one rclpy checker process that subscribes to every ROS topic
and publishes every robot's ``cmd_vel``. Each robot's messages carry its index, so every topic
is checked to bring its own robot's values, both ways, at the issue's rates (about 4,600
messages a second; ``benchmarks/fleet.py`` measures what that costs), and on the native path
the bridge has no more threads than the C++ bridge for the same fleet (20, issue 28). The same
with one robot of ``config/fleet_robot.yaml``, the C++ bridge's form of the example, in its
namespace.
"""

from __future__ import annotations

import functools
import os
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

from ros_gz_bridge_py.native import extension
from ros_gz_bridge_py.transport.settings import planned_rcvhwm
from testing import fleet_sim
from testing.behaviour_harness import bridge_command
from testing.e2e_harness import (
    RUN_TIMEOUT,
    ProcessGroup,
    RosChecker,
    lines,
    parse_gz,
    status_rows,
    wait_all,
)
from testing.gzpeer import ROOT, PeerProcess, require_peer, wait_for_line
from testing.procstat import threads_of
from tests.bridge.e2e_values import mismatches

pytestmark = [pytest.mark.peer, pytest.mark.ros]

ROBOTS = fleet_sim.robots(10)
#: The C++ bridge's threads for a fleet, whatever its size (issue 28, measured beside it).
CPP_BRIDGE_THREADS = 20


@pytest.fixture
def group() -> Iterator[ProcessGroup]:
    processes = ProcessGroup()
    yield processes
    processes.stop()


def _arrived(checker: RosChecker, topic: str, expected: dict[str, Any]) -> bool:
    return any(not mismatches(expected, msg) for msg in checker.messages(topic))


def test_ten_robots_flow_both_ways_through_one_templated_file(
    group: ProcessGroup, tmp_path: Path
) -> None:
    bridge = check_fleet(group, tmp_path, ROBOTS, fleet_sim.bridge_arguments(ROBOTS), clock=True)
    # /clock, and odom, imu, joint_states a robot: the receive queue of a topic with a socket
    # of its own planned smaller than gz-transport's 1000, so that a fleet's queues stay near
    # 64 MiB together; the socket the native channels share keeps 1000 per publisher.
    topics = 1 + 3 * len(ROBOTS)
    planned = planned_rcvhwm(topics)
    assert (
        f"{topics} Gazebo topics: the ZeroMQ receive queue of each topic with a socket of its "
        f"own holds {planned} messages, that of the socket the native channels of small "
        "messages share 1000 per publisher"
    ) in bridge.output()
    assert planned < 1000
    if extension() is not None and os.environ.get("ROS_GZ_BRIDGE_NATIVE", "on") != "off":
        # Two loops carry the 41 native channels: no thread per channel.
        assert threads_of(bridge) <= CPP_BRIDGE_THREADS


def test_the_cpp_bridges_per_robot_form_works_in_a_namespace(
    group: ProcessGroup, tmp_path: Path
) -> None:
    """``config/fleet_robot.yaml`` (relative names) under ``-r __ns:=/robot_7``, as one
    C++ bridge node of the fleet would load it."""
    robot = "robot_7"
    arguments = [
        *("--ros-args", "-r", f"__ns:=/{robot}"),
        *("-p", f"config_file:={fleet_sim.CONFIG.with_name('fleet_robot.yaml')}"),
        *("-p", "expand_gz_topic_names:=true"),
    ]
    check_fleet(group, tmp_path, [robot], arguments, clock=False)


def check_fleet(
    group: ProcessGroup, tmp_path: Path, robots: list[str], arguments: list[str], *, clock: bool
) -> PeerProcess:
    """The simulator publishing the fleet of ``robots``, ``parameter_bridge ARGUMENTS`` and
    the checker: every Gazebo -> ROS topic (``/clock`` too with ``clock``) brings its own
    robot's values to ROS, and every robot's ``cmd_vel`` reaches the simulator with its own.
    Returns the bridge, still running."""
    require_peer()
    spec = fleet_sim.write_spec(tmp_path / "fleet.spec", robots)
    simulator = group.peer("pub-fleet", str(spec), "0")
    wait_for_line(simulator, r"^READY$", timeout=30)
    # This checkout's package, whichever the console script's environment installed.
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    bridge = group.start(bridge_command(*arguments), env)
    expected: dict[str, dict[str, Any]] = {}
    types: dict[str, str] = {}
    if clock:
        expected[fleet_sim.CLOCK_TOPIC] = fleet_sim.CLOCK_ROS
        types[fleet_sim.CLOCK_TOPIC] = "rosgraph_msgs/msg/Clock"
    for robot in robots:
        for kind in fleet_sim.KINDS:
            expected[kind.topic(robot)] = fleet_sim.expected_ros(kind, robot)
            types[kind.topic(robot)] = kind.ros_type
    commands = [
        (fleet_sim.cmd_vel_topic(robot), fleet_sim.CMD_VEL_TYPE, fleet_sim.cmd_vel_values(robot))
        for robot in robots
    ]
    checker = RosChecker(group, list(types.items()), commands)

    to_ros = wait_all(
        {
            topic: functools.partial(_arrived, checker, topic, want)
            for topic, want in expected.items()
        },
        RUN_TIMEOUT,
    )
    missing = {
        topic: checker.messages(topic)[:1] for topic, arrived in to_ros.items() if not arrived
    }
    assert not missing, (
        f"Gazebo -> ROS, not (or wrongly) arrived: {missing}; the bridge's status of those:\n"
        + "\n".join(status_rows(bridge, list(missing)))
    )

    def command_arrived(robot: str) -> bool:
        prefix = f"FIRST {fleet_sim.cmd_vel_topic(robot)} "
        return any(
            not mismatches(fleet_sim.cmd_vel_values(robot), _twist(text))
            for text in lines(simulator, prefix)
        )

    to_gz = wait_all(
        {robot: functools.partial(command_arrived, robot) for robot in robots}, RUN_TIMEOUT
    )
    firsts = lines(simulator, "FIRST ")
    assert all(to_gz.values()), f"ROS -> Gazebo: {to_gz}; the simulator saw {firsts}"
    return bridge


def _twist(text: str) -> dict[str, dict[str, float]]:
    """The C++ peer's one-line Twist as the fields ``cmd_vel_values`` names."""
    twist = parse_gz("Twist", text)
    return {
        "linear": {"x": twist.linear.x, "y": twist.linear.y, "z": twist.linear.z},
        "angular": {"x": twist.angular.x, "y": twist.angular.y, "z": twist.angular.z},
    }

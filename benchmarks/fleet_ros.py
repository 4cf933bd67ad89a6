"""The ROS ends of ``benchmarks.fleet``: the fleet's ROS subscriber, and a bare rclpy publisher.

``python -m benchmarks.fleet_ros sub ROBOTS`` subscribes to every Gazebo -> ROS topic of the
fleet of ``testing/fleet_sim.py`` (``/clock``, and each robot's odom, imu, joint_states), taking
the messages serialized (rclpy's ``raw=True``: no deserialization, as a recorder or a relay
would) and counting them per topic; it publishes every robot's ``cmd_vel`` at 10 Hz from the
moment the bridge subscribes to it. Lines: ``READY``; ``ALL_FLOWING <wall time>`` once every
topic has brought a message; on SIGUSR1 ``COUNTS <json>`` (messages per topic so far, and
``cmd_vel`` sent); ends on SIGTERM.

``python -m benchmarks.fleet_ros pub ROBOTS`` is the ceiling's publisher: one rclpy process
publishing the same topics at the same rates, each message serialized once, with no Gazebo
side and no conversion: what an rclpy process pays for the fleet's ROS traffic alone.
Lines: ``READY``, then ``SENT n`` when stopped.
"""

from __future__ import annotations

import argparse
import importlib
import json
import os
import signal
import sys
import threading
import time
from typing import Any

from benchmarks.workers import _ros_qos, _ros_start, say
from testing import fleet_sim
from testing.e2e_ros_checker import fill

CLOCK_TYPE = "rosgraph_msgs/msg/Clock"


def ros_class(name: str) -> Any:
    """The rclpy class of ``pkg/msg/Name``."""
    package, _, type_name = name.split("/")
    return getattr(importlib.import_module(f"{package}.msg"), type_name)


def gz_to_ros_topics(robots: int) -> list[tuple[str, str, float]]:
    """``(topic, ROS type, Hz)`` of every Gazebo -> ROS topic of the fleet."""
    topics = [(fleet_sim.CLOCK_TOPIC, CLOCK_TYPE, fleet_sim.CLOCK_HZ)]
    for robot in fleet_sim.robots(robots):
        topics += [(kind.topic(robot), kind.ros_type, kind.hz) for kind in fleet_sim.KINDS]
    return topics


def _spin(executor: Any, stop: threading.Event) -> None:
    from rclpy.task import Future  # noqa: PLC0415 - rclpy is loaded by _ros_start

    never: Future = Future(executor=executor)
    while not stop.is_set():
        executor.spin_until_future_complete(never, timeout_sec=0.5)


def subscriber(robots: int) -> None:
    rclpy = _ros_start()
    from ros_gz_bridge_py.app.settings import read_switches  # noqa: PLC0415
    from ros_gz_bridge_py.ros.runtime import make_executor  # noqa: PLC0415

    node = rclpy.create_node(f"fleet_sub_{os.getpid()}")
    topics = gz_to_ros_topics(robots)
    counts = dict.fromkeys((topic for topic, _, _ in topics), 0)
    waiting = set(counts)

    def counter(topic: str) -> Any:
        def on_message(_msg: bytes) -> None:
            counts[topic] += 1
            if counts[topic] == 1:
                waiting.discard(topic)
                if not waiting:
                    say(f"ALL_FLOWING {time.time():.6f}")

        return on_message

    for topic, type_name, _ in topics:
        node.create_subscription(ros_class(type_name), topic, counter(topic), _ros_qos(), raw=True)
    twist_class = ros_class(fleet_sim.CMD_VEL_TYPE)
    commands = []
    for robot in fleet_sim.robots(robots):
        twist = twist_class()
        twist.linear.x = fleet_sim.cmd_vel_values(robot)["linear"]["x"]
        publisher = node.create_publisher(twist_class, fleet_sim.cmd_vel_topic(robot), _ros_qos())
        commands.append((publisher, twist))
    sent = [0]

    def command() -> None:
        for publisher, twist in commands:
            if publisher.get_subscription_count() > 0:
                publisher.publish(twist)
                sent[0] += 1

    node.create_timer(1.0 / fleet_sim.CMD_VEL_HZ, command)
    stop = threading.Event()
    signal.signal(signal.SIGTERM, lambda *_: stop.set())
    signal.signal(
        signal.SIGUSR1, lambda *_: say(f"COUNTS {json.dumps({**counts, 'cmd_vel': sent[0]})}")
    )
    executor = make_executor(events=read_switches().events_executor)
    executor.add_node(node)
    spinning = threading.Thread(target=_spin, args=(executor, stop), daemon=True)
    spinning.start()
    say("READY")
    while not stop.wait(0.5):
        pass
    spinning.join(timeout=2)
    try:
        node.destroy_node()
        rclpy.try_shutdown()
    finally:
        os._exit(0)


def _filled(type_name: str, topic: str) -> Any:
    """The ROS message the bridge makes of ``topic``'s Gazebo message (the fields it sets)."""
    msg = ros_class(type_name)()
    if type_name == CLOCK_TYPE:
        msg.clock.sec = fleet_sim.CLOCK_ROS["clock"]["sec"]
        return msg
    robot = topic.split("/")[1]
    kind = next(kind for kind in fleet_sim.KINDS if kind.topic(robot) == topic)
    fill(msg, fleet_sim.expected_ros(kind, robot))
    return msg


def publisher(robots: int) -> None:
    """Publish every topic on its own schedule, as the C++ peer's ``pub-fleet`` does."""
    rclpy = _ros_start()
    from rclpy.serialization import serialize_message  # noqa: PLC0415

    node = rclpy.create_node(f"fleet_pub_{os.getpid()}")
    schedule = []
    for topic, type_name, hz in gz_to_ros_topics(robots):
        pub = node.create_publisher(ros_class(type_name), topic, _ros_qos())
        schedule.append([0.0, 1.0 / hz, pub, serialize_message(_filled(type_name, topic))])
    stop = threading.Event()
    signal.signal(signal.SIGTERM, lambda *_: stop.set())
    say("READY")
    start = time.monotonic()
    for entry in schedule:
        entry[0] = start
    sent = 0
    while not stop.is_set():
        now = time.monotonic()
        wake = now + 1.0
        for entry in schedule:
            if entry[0] <= now:
                entry[2].publish(entry[3])
                sent += 1
                entry[0] = max(entry[0] + entry[1], now - 1.0)
            wake = min(wake, entry[0])
        delay = wake - time.monotonic()
        if delay > 0:
            time.sleep(delay)
    say(f"SENT {sent}")
    try:
        node.destroy_node()
        rclpy.try_shutdown()
    finally:
        os._exit(0)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("role", choices=("sub", "pub"))
    parser.add_argument("robots", type=int)
    args = parser.parse_args(argv)
    (subscriber if args.role == "sub" else publisher)(args.robots)
    return 0


if __name__ == "__main__":
    sys.exit(main())

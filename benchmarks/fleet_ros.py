"""The ROS ends of ``benchmarks.fleet``: the fleet's ROS subscribers, and a bare rclpy publisher.

The subscribers live in several processes, as a fleet's ROS side does (a node per robot stack,
a logger): ``/clock`` in a process of its own, and at most :data:`ROBOTS_PER_PROCESS` robots
per process (:func:`parts`). ``python -m benchmarks.fleet_ros sub --clock`` subscribes to
``/clock``; ``python -m benchmarks.fleet_ros sub --robots FIRST LAST`` to the odom, imu and
joint_states of robots FIRST..LAST of ``testing/fleet_sim.py``, and publishes their
``cmd_vel`` at 10 Hz from the moment something subscribes to it (the robots' commands live
with their subscribers). Every subscription takes the messages serialized (rclpy's
``raw=True``: no deserialization, as a recorder or a relay would) and counts them per topic.
Lines: ``READY``; ``ALL_FLOWING <wall time>`` once every topic of the process has brought a
message; on SIGUSR1 ``COUNTS <json>`` (messages per topic so far, and ``cmd_vel`` sent); ends
on SIGTERM.

``python -m benchmarks.fleet_ros pub ROBOTS`` is the ceiling's ROS end: one rclpy process
publishing the same topics at the same rates, each message serialized once, and subscribed
(serialized) to every robot's ``cmd_vel``, with no Gazebo side and no conversion: what an
rclpy process pays for the fleet's ROS traffic alone, where the bridge is. Lines: ``READY``;
on SIGUSR1 ``COUNTS {"cmd_vel": received}``; ``SENT n`` when stopped. With ``--at-rest`` it
makes the same publishers and subscriptions and sends nothing: the ceiling of an idle bridge.
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
from collections.abc import Callable
from typing import Any

from benchmarks.workers import _ros_qos, _ros_start, say
from testing import fleet_sim
from testing.e2e_ros_checker import fill

CLOCK_TYPE = "rosgraph_msgs/msg/Clock"
#: Most robots one subscriber process takes.
ROBOTS_PER_PROCESS = 10


def ros_class(name: str) -> Any:
    """The rclpy class of ``pkg/msg/Name``."""
    package, _, type_name = name.split("/")
    return getattr(importlib.import_module(f"{package}.msg"), type_name)


def parts(robots: int) -> list[list[str]]:
    """The ``sub`` arguments of each subscriber process of a fleet of ``robots``: ``/clock``
    alone, then the robots ten by ten."""
    layout = [["--clock"]]
    for first in range(1, robots + 1, ROBOTS_PER_PROCESS):
        last = min(first + ROBOTS_PER_PROCESS - 1, robots)
        layout.append(["--robots", str(first), str(last)])
    return layout


def robot_topics(names: list[str]) -> list[tuple[str, str, float]]:
    """``(topic, ROS type, Hz)`` of the Gazebo -> ROS topics of the robots ``names``."""
    return [
        (kind.topic(robot), kind.ros_type, kind.hz) for robot in names for kind in fleet_sim.KINDS
    ]


def gz_to_ros_topics(robots: int) -> list[tuple[str, str, float]]:
    """``(topic, ROS type, Hz)`` of every Gazebo -> ROS topic of the fleet."""
    clock = (fleet_sim.CLOCK_TOPIC, CLOCK_TYPE, fleet_sim.CLOCK_HZ)
    return [clock, *robot_topics(fleet_sim.robots(robots))]


def _spin(executor: Any, stop: threading.Event) -> None:
    from rclpy.task import Future  # noqa: PLC0415 - rclpy is loaded by _ros_start

    never: Future = Future(executor=executor)
    while not stop.is_set():
        executor.spin_until_future_complete(never, timeout_sec=0.5)


def _serve(node: Any, report: Callable[[], dict[str, int]]) -> None:
    """Spin ``node`` until SIGTERM, printing ``COUNTS`` on SIGUSR1; then leave at once."""
    from ros_gz_bridge_py.app.settings import read_switches  # noqa: PLC0415
    from ros_gz_bridge_py.ros.runtime import make_executor  # noqa: PLC0415

    stop = threading.Event()
    signal.signal(signal.SIGTERM, lambda *_: stop.set())
    signal.signal(signal.SIGUSR1, lambda *_: say(f"COUNTS {json.dumps(report())}"))
    executor = make_executor(events=read_switches().events_executor)
    executor.add_node(node)
    spinning = threading.Thread(target=_spin, args=(executor, stop), daemon=True)
    spinning.start()
    say("READY")
    while not stop.wait(0.5):
        pass
    spinning.join(timeout=2)
    _leave(node)


def _leave(node: Any) -> None:
    """Destroy ``node`` and leave at once (``os._exit``: no waiting on rclpy's threads)."""
    import rclpy  # noqa: PLC0415

    try:
        node.destroy_node()
        rclpy.try_shutdown()
    finally:
        os._exit(0)


def subscriber(names: list[str], clock: bool) -> None:
    """Count the topics of ``names`` (and ``/clock`` with ``clock``); command ``names``."""
    rclpy = _ros_start()
    node = rclpy.create_node(f"fleet_sub_{os.getpid()}")
    topics = robot_topics(names)
    if clock:
        topics.insert(0, (fleet_sim.CLOCK_TOPIC, CLOCK_TYPE, fleet_sim.CLOCK_HZ))
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
    for robot in names:
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

    if commands:
        node.create_timer(1.0 / fleet_sim.CMD_VEL_HZ, command)
    _serve(node, lambda: {**counts, "cmd_vel": sent[0]})


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


def publisher(robots: int, at_rest: bool = False) -> None:
    """Publish every topic on its own schedule, as the C++ peer's ``pub-fleet`` does (none
    ``at_rest``), and take every robot's ``cmd_vel`` serialized, as the bridge does."""
    rclpy = _ros_start()
    from rclpy.serialization import serialize_message  # noqa: PLC0415

    node = rclpy.create_node(f"fleet_pub_{os.getpid()}")
    schedule = []
    for topic, type_name, hz in gz_to_ros_topics(robots):
        pub = node.create_publisher(ros_class(type_name), topic, _ros_qos())
        schedule.append([0.0, 1.0 / hz, pub, serialize_message(_filled(type_name, topic))])
    received = [0]

    def on_command(_msg: bytes) -> None:
        received[0] += 1

    twist_class = ros_class(fleet_sim.CMD_VEL_TYPE)
    for robot in fleet_sim.robots(robots):
        topic = fleet_sim.cmd_vel_topic(robot)
        node.create_subscription(twist_class, topic, on_command, _ros_qos(), raw=True)
    stop = threading.Event()
    signal.signal(signal.SIGTERM, lambda *_: stop.set())
    signal.signal(signal.SIGUSR1, lambda *_: say(f"COUNTS {json.dumps({'cmd_vel': received[0]})}"))
    serving = threading.Thread(
        target=_serve_commands, args=(node, stop), daemon=True
    )  # the subscriptions spin beside the schedule, as the bridge's executor does
    serving.start()
    say("READY")
    start = time.monotonic()
    for entry in schedule:
        entry[0] = start
    sent = 0
    if at_rest:
        stop.wait()  # a signal's handler runs in this wait (it sets `stop`)
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
    _leave(node)


def _serve_commands(node: Any, stop: threading.Event) -> None:
    """The ceiling's executor, spinning its ``cmd_vel`` subscriptions until ``stop``."""
    from ros_gz_bridge_py.app.settings import read_switches  # noqa: PLC0415
    from ros_gz_bridge_py.ros.runtime import make_executor  # noqa: PLC0415

    executor = make_executor(events=read_switches().events_executor)
    executor.add_node(node)
    _spin(executor, stop)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    sub = parser.add_subparsers(dest="role", required=True)
    subscribing = sub.add_parser("sub", help="a subscriber process of the layout (parts())")
    subscribing.add_argument("--clock", action="store_true", help="subscribe to /clock")
    subscribing.add_argument(
        "--robots", type=int, nargs=2, metavar=("FIRST", "LAST"), help="robots FIRST..LAST"
    )
    publishing = sub.add_parser("pub", help="the ceiling's rclpy process")
    publishing.add_argument("robots", type=int)
    publishing.add_argument("--at-rest", action="store_true", help="send nothing")
    args = parser.parse_args(argv)
    if args.role == "pub":
        publisher(args.robots, args.at_rest)
        return 0
    first, last = args.robots or (1, 0)
    subscriber([f"robot_{i}" for i in range(first, last + 1)], args.clock)
    return 0


if __name__ == "__main__":
    sys.exit(main())

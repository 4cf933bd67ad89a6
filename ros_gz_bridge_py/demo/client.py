"""The demo's ROS side: drives the robot in a circle and watches every bridged topic.

Subscriptions are best effort, so they match the bridge's publishers whatever their
reliability. Latency is wall time at the callback minus the message stamp (the world stamps
with the wall clock); for ``/clock`` the stamp is the clock value itself.
"""

from __future__ import annotations

import importlib
import math
import sys
import time
from collections.abc import Callable
from typing import Any, TextIO

from geometry_msgs.msg import Twist
from rclpy.executors import SingleThreadedExecutor
from rclpy.node import Node
from rclpy.qos import QoSProfile, ReliabilityPolicy

from ros_gz_bridge_py.demo import topics
from ros_gz_bridge_py.demo.report import Pose2D, TopicStats, format_pose, format_rows

LINEAR_SPEED = 0.2
ANGULAR_SPEED = 0.4
COMMAND_PERIOD = 0.1
REFRESH_PERIOD = 1.0
NODE_NAME = "ros_gz_bridge_demo_client"
#: Polled between spins: a reason to stop (shown to the user), or None to go on.
StopCheck = Callable[[], str | None]


def ros_message_class(ros_type: str) -> type[Any]:
    """The class of ``pkg/msg/Name``."""
    package, _, name = ros_type.split("/")
    cls: type[Any] = getattr(importlib.import_module(f"{package}.msg"), name)
    return cls


def message_stamp(msg: Any) -> float | None:
    """The message's time in seconds: header stamp, Clock value, or first transform's stamp."""
    if hasattr(msg, "header"):
        stamp = msg.header.stamp
    elif hasattr(msg, "clock"):
        stamp = msg.clock
    elif getattr(msg, "transforms", None):
        stamp = msg.transforms[0].header.stamp
    else:
        return None
    return float(stamp.sec) + float(stamp.nanosec) * 1e-9


def odometry_pose(msg: Any) -> Pose2D:
    position = msg.pose.pose.position
    q = msg.pose.pose.orientation
    yaw = math.atan2(2.0 * (q.w * q.z + q.x * q.y), 1.0 - 2.0 * (q.y * q.y + q.z * q.z))
    return Pose2D(position.x, position.y, yaw)


class DemoClient:
    """An rclpy node publishing ``cmd_vel`` and counting every bridged Gazebo -> ROS topic."""

    def __init__(self, node: Node) -> None:
        self.node = node
        self.stats = {topic.name: TopicStats(topic) for topic in topics.GZ_TO_ROS}
        self.first_pose: Pose2D | None = None
        self.pose: Pose2D | None = None
        qos = QoSProfile(depth=10, reliability=ReliabilityPolicy.BEST_EFFORT)
        for topic in topics.GZ_TO_ROS:
            node.create_subscription(
                ros_message_class(topic.ros_type), topic.name, self._recorder(topic.name), qos
            )
        self._cmd_vel = node.create_publisher(Twist, topics.CMD_VEL, 10)
        self._command = Twist()
        self._command.linear.x = LINEAR_SPEED
        self._command.angular.z = ANGULAR_SPEED
        node.create_timer(COMMAND_PERIOD, lambda: self._cmd_vel.publish(self._command))

    def _recorder(self, name: str) -> Callable[[Any], None]:
        stats = self.stats[name]

        def record(msg: Any) -> None:
            stats.record(time.time(), message_stamp(msg))
            if name == topics.ODOM:
                self.pose = odometry_pose(msg)
                if self.first_pose is None:
                    self.first_pose = self.pose

        return record

    def unmatched(self) -> list[str]:
        """Topics without a bridge endpoint yet (no publisher, or nobody takes cmd_vel)."""
        missing = [
            f"/{topic.name}"
            for topic in topics.GZ_TO_ROS
            if self.node.count_publishers(topic.name) == 0
        ]
        if self._cmd_vel.get_subscription_count() == 0:
            missing.append(f"/{topics.CMD_VEL}")
        return missing


def wait_for_bridge(
    client: DemoClient, executor: SingleThreadedExecutor, timeout: float, stop: StopCheck
) -> list[str]:
    """Spin until every topic has its bridge endpoint; what is still missing (or [])."""
    deadline = time.monotonic() + timeout
    while (missing := client.unmatched()) and time.monotonic() < deadline and stop() is None:
        executor.spin_once(timeout_sec=0.1)
    return missing


def watch(
    client: DemoClient,
    executor: SingleThreadedExecutor,
    stop: StopCheck,
    out: TextIO = sys.stdout,
) -> str:
    """Spin and print the live table every REFRESH_PERIOD until ``stop`` gives a reason.

    On a terminal each table is redrawn in place (ANSI cursor-up); piped, tables follow each
    other. Returns the reason.
    """
    started = time.monotonic()
    next_refresh = started + REFRESH_PERIOD
    redraw = out.isatty()
    drawn = 0
    for stats in client.stats.values():
        stats.window(time.time())
    while (reason := stop()) is None:
        executor.spin_once(timeout_sec=min(0.05, max(next_refresh - time.monotonic(), 0.0)))
        if time.monotonic() < next_refresh:
            continue
        next_refresh += REFRESH_PERIOD
        now = time.time()
        rows = [stats.window(now) for stats in client.stats.values()]
        lines = [
            f"--- {time.monotonic() - started:6.1f} s ---",
            *format_rows(rows),
            format_pose(client.pose),
        ]
        if redraw and drawn:
            out.write(f"\x1b[{drawn}F\x1b[J")
        out.write("\n".join(lines) + "\n")
        out.flush()
        drawn = len(lines)
    return reason

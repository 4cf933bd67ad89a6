"""The ROS side of the soak (``testing/soak.py``): ``python soak_ros.py SPEC``.

SPEC is JSON: ``{"clock": t, "odom": t, "cmd": t, "service": s, "seconds": n}``. Subscribes to
the clock and odometry topics, publishes ``Twist`` on ``cmd`` at 50 Hz (``linear.x`` = 1, 2, ...),
calls the ``ControlWorld`` service every 0.2 s (at most 10 calls waiting), and every 2 s makes
and destroys an extra odometry subscription (ROS endpoint churn). Prints ``STATS {json}`` once
a second and at the end: counts so far, and the times of the odometry messages' gaps.
"""

from __future__ import annotations

import json
import sys
import time
from typing import Any

import rclpy
from geometry_msgs.msg import Twist
from nav_msgs.msg import Odometry
from rclpy.executors import SingleThreadedExecutor
from rclpy.qos import QoSProfile
from rclpy.signals import SignalHandlerOptions
from ros_gz_interfaces.srv import ControlWorld
from rosgraph_msgs.msg import Clock

from ros_gz_bridge_py.ros.stop_signal import StopSignal

CMD_PERIOD = 0.02
CALL_PERIOD = 0.2
CHURN_PERIOD = 2.0
MAX_WAITING_CALLS = 10
#: Seconds the node lives on after its last command, so that command reaches the bridge.
LINGER = 0.5


class Counts:
    def __init__(self) -> None:
        self.clock = 0
        self.odom = 0
        self.cmd_sent = 0
        self.calls = 0
        self.answered = 0
        self.succeeded = 0
        self.churned = 0
        self.last_odom = time.monotonic()
        #: (when, seconds) of every pause of 1 s or more in the odometry stream.
        self.odom_gaps: list[tuple[float, float]] = []

    def on_odom(self, _msg: Any) -> None:
        now = time.monotonic()
        if now - self.last_odom >= 1.0 and self.odom:
            self.odom_gaps.append((round(now, 3), round(now - self.last_odom, 3)))
        self.last_odom = now
        self.odom += 1


def main() -> int:
    spec = json.loads(sys.argv[1])
    with StopSignal() as stop:
        rclpy.init(signal_handler_options=SignalHandlerOptions.NO)
        node = rclpy.create_node("soak_ros")
        counts = Counts()
        depth = QoSProfile(depth=200)

        def on_clock(_msg: Any) -> None:
            counts.clock += 1

        node.create_subscription(Clock, spec["clock"], on_clock, depth)
        node.create_subscription(Odometry, spec["odom"], counts.on_odom, depth)
        publisher = node.create_publisher(Twist, spec["cmd"], 10)
        client = node.create_client(ControlWorld, spec["service"])
        executor = SingleThreadedExecutor()
        executor.add_node(node)
        waiting: list[Any] = []
        extra: Any = None
        start = time.monotonic()
        next_cmd = next_call = next_churn = next_stats = start
        end = start + float(spec["seconds"])
        while not stop.requested and time.monotonic() < end:
            executor.spin_once(timeout_sec=0.005)
            now = time.monotonic()
            # Commands start once the bridge's subscription is matched: a volatile reliable
            # writer does not keep what it wrote before.
            if now >= next_cmd and publisher.get_subscription_count() > 0:
                counts.cmd_sent += 1
                message = Twist()
                message.linear.x = float(counts.cmd_sent)
                publisher.publish(message)
                next_cmd += CMD_PERIOD
            if now >= next_call and client.service_is_ready() and len(waiting) < MAX_WAITING_CALLS:
                request = ControlWorld.Request()
                request.world_control.pause = counts.calls % 2 == 0
                waiting.append(client.call_async(request))
                counts.calls += 1
                next_call = now + CALL_PERIOD
            for future in [f for f in waiting if f.done()]:
                waiting.remove(future)
                counts.answered += 1
                counts.succeeded += bool(future.result().success)
            if now >= next_churn:
                if extra is None:
                    extra = node.create_subscription(Odometry, spec["odom"], lambda _m: None, 10)
                else:
                    node.destroy_subscription(extra)
                    extra = None
                counts.churned += 1
                next_churn = now + CHURN_PERIOD
            if now >= next_stats:
                print_stats(counts, len(waiting))
                next_stats = now + 1.0
        # Reliable samples just written are delivered while the node lives, not after.
        linger_until = time.monotonic() + LINGER
        while time.monotonic() < linger_until:
            executor.spin_once(timeout_sec=0.05)
        print_stats(counts, len(waiting))
        node.destroy_node()
        rclpy.try_shutdown()
    return 0


def print_stats(counts: Counts, waiting: int) -> None:
    stats = {k: v for k, v in vars(counts).items() if k != "last_odom"}
    stats["waiting"] = waiting
    sys.stdout.write(f"STATS {json.dumps(stats)}\n")
    sys.stdout.flush()


if __name__ == "__main__":
    sys.exit(main())

"""The ROS host's probe in the two-host tests: ``python ros_probe.py CLOCK CMD SECONDS``.

Subscribes to a ``rosgraph_msgs/msg/Clock`` topic and prints ``CLOCK <sec> <nanosec>`` for each
message; publishes ``geometry_msgs/msg/Twist`` on the other topic at 20 Hz with ``linear.x`` =
1, 2, 3, ... and prints ``SENT <n>`` for each. Ends after SECONDS or on SIGTERM.
"""

from __future__ import annotations

import sys
import time

import rclpy
from geometry_msgs.msg import Twist
from rclpy.executors import SingleThreadedExecutor
from rclpy.qos import QoSProfile
from rclpy.signals import SignalHandlerOptions
from rosgraph_msgs.msg import Clock

from ros_gz_bridge_py.ros.stop_signal import StopSignal

PERIOD = 0.05


def emit(text: str) -> None:
    sys.stdout.write(text + "\n")
    sys.stdout.flush()


def main() -> int:
    clock_topic, cmd_topic, seconds = sys.argv[1], sys.argv[2], float(sys.argv[3])
    with StopSignal() as stop:
        rclpy.init(signal_handler_options=SignalHandlerOptions.NO)
        node = rclpy.create_node("two_host_probe")
        node.create_subscription(
            Clock, clock_topic, lambda m: emit(f"CLOCK {m.clock.sec} {m.clock.nanosec}"),
            QoSProfile(depth=100),
        )  # fmt: skip
        publisher = node.create_publisher(Twist, cmd_topic, 10)
        executor = SingleThreadedExecutor()
        executor.add_node(node)
        emit("READY")
        sequence = 0
        next_send = time.monotonic()
        end = time.monotonic() + seconds
        while not stop.requested and time.monotonic() < end:
            executor.spin_once(timeout_sec=0.01)
            if time.monotonic() >= next_send:
                sequence += 1
                message = Twist()
                message.linear.x = float(sequence)
                publisher.publish(message)
                emit(f"SENT {sequence}")
                next_send += PERIOD
        node.destroy_node()
        rclpy.try_shutdown()
    return 0


if __name__ == "__main__":
    sys.exit(main())

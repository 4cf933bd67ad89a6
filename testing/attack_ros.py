"""The ROS side of the attack suite (``testing/attacks.py``): ``python attack_ros.py SPEC``.

SPEC is JSON: ``{"clock": t, "odom": t, "tf": t, "seconds": n}``. Subscribes to the three
topics as serialized messages (no deserialization: the counting must not be the bottleneck)
and prints ``COUNTS {json}`` four times a second until ``seconds`` have passed or it is
stopped: the time (``time.monotonic()``, the same clock in every process of the host), the
messages of each topic so far, the Odometry messages of the real publisher (its
``child_frame_id`` is ``real``) and the largest serialized message of each topic.
"""

from __future__ import annotations

import json
import sys
import time

import rclpy
from nav_msgs.msg import Odometry
from rclpy.executors import SingleThreadedExecutor
from rclpy.qos import QoSProfile
from rclpy.signals import SignalHandlerOptions
from rosgraph_msgs.msg import Clock
from tf2_msgs.msg import TFMessage

from ros_gz_bridge_py.ros.stop_signal import StopSignal

PRINT_EVERY = 0.25
#: What the real Odometry publisher puts in child_frame_id (``testing/attacks.py``).
REAL_MARK = b"real"


def main() -> int:
    spec = json.loads(sys.argv[1])
    counts = {"clock": 0, "odom": 0, "odom_real": 0, "tf": 0}
    largest = {"clock": 0, "odom": 0, "tf": 0}

    def counter(name: str) -> object:
        def count(data: bytes) -> None:
            counts[name] += 1
            largest[name] = max(largest[name], len(data))
            if name == "odom" and REAL_MARK in data:
                counts["odom_real"] += 1

        return count

    with StopSignal() as stop:
        rclpy.init(signal_handler_options=SignalHandlerOptions.NO)
        node = rclpy.create_node("attack_ros")
        depth = QoSProfile(depth=1000)
        for name, msg_type in (("clock", Clock), ("odom", Odometry), ("tf", TFMessage)):
            node.create_subscription(msg_type, spec[name], counter(name), depth, raw=True)
        executor = SingleThreadedExecutor()
        executor.add_node(node)
        end = time.monotonic() + float(spec["seconds"])
        next_print = time.monotonic()
        while not stop.requested and time.monotonic() < end:
            executor.spin_once(timeout_sec=0.01)
            now = time.monotonic()
            if now >= next_print:
                record = {"t": now, **counts, "largest": largest}
                sys.stdout.write(f"COUNTS {json.dumps(record)}\n")
                sys.stdout.flush()
                next_print = now + PRINT_EVERY
        node.destroy_node()
        rclpy.try_shutdown()
    return 0


if __name__ == "__main__":
    sys.exit(main())

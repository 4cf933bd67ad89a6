"""Embed the bridge in your own rclpy program and change its bridges at run time.

The program owns the rclpy node and the executor; ``Bridge`` only adds channels to that node
(and opens one Gazebo Transport node of its own). It:

1. bridges ``--first`` (Gazebo -> ROS, ``std_msgs/msg/String``) and prints the first message,
2. removes that bridge (the Gazebo subscription and the ROS publisher go away),
3. bridges ``--second`` the same way and prints its first message,
4. closes the bridge and shuts rclpy down.

Run it next to Gazebo publishers of both topics that keep publishing, for example::

    while sleep 0.5; do gz topic -t /first -m gz.msgs.StringMsg -p 'data: "hello"'; done &
    while sleep 0.5; do gz topic -t /second -m gz.msgs.StringMsg -p 'data: "again"'; done &
    python examples/embed_bridge.py --first /first --second /second

It prints one line per step (``RECEIVED <topic> <data>``, ``REMOVED <topic>``, ``DONE``) and
exits with status 1 if a message does not arrive within ``--timeout`` seconds. Ctrl-C closes the
bridge, then shuts rclpy down (rclpy's own signal handler would shut it down first), prints
``INTERRUPTED`` and exits with status 130.
"""

from __future__ import annotations

import argparse
import sys
import threading
from typing import Any

import rclpy
from rclpy.executors import SingleThreadedExecutor
from rclpy.signals import SignalHandlerOptions
from std_msgs.msg import String

from ros_gz_bridge_py import Bridge, BridgeOptions
from ros_gz_bridge_py.config import Direction, TopicBridgeSpec


def first_message(node: Any, topic: str, timeout: float) -> str | None:
    """Subscribe to ``topic`` on our own node and wait for one message's text."""
    arrived = threading.Event()
    texts: list[str] = []

    def on_message(msg: Any) -> None:
        texts.append(msg.data)
        arrived.set()

    subscription = node.create_subscription(String, topic, on_message, 10)
    try:
        arrived.wait(timeout)
        return texts[0] if texts else None
    finally:
        node.destroy_subscription(subscription)


def gz_to_ros(topic: str, gz_type: str) -> TopicBridgeSpec:
    return TopicBridgeSpec(
        ros_topic=topic,
        gz_topic=topic,
        ros_type="std_msgs/msg/String",
        gz_type=gz_type,
        direction=Direction.GZ_TO_ROS,
    )


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--first", default="/first", help="Gazebo topic bridged first")
    parser.add_argument("--second", default="/second", help="Gazebo topic bridged after it")
    parser.add_argument("--gz-type", default="gz.msgs.StringMsg",
                        help="Gazebo type name (either spelling matches every line)")  # fmt: skip
    parser.add_argument("--timeout", type=float, default=20.0, help="seconds per message")
    args = parser.parse_args()

    # Ctrl-C is ours to handle: the bridge closes before rclpy shuts down.
    rclpy.init(signal_handler_options=SignalHandlerOptions.NO)
    node = rclpy.create_node("embed_bridge_example")
    executor = SingleThreadedExecutor()
    executor.add_node(node)
    spinner = threading.Thread(target=executor.spin, daemon=True)
    spinner.start()
    status = 0
    # The bridge adds its channels and its lazy-check timer to *our* node.
    bridge = Bridge(node, options=BridgeOptions(heartbeat=0.5))
    try:
        for step, topic in enumerate((args.first, args.second)):
            handle = bridge.add(gz_to_ros(topic, args.gz_type))
            print(f"ADDED {topic}", flush=True)
            text = first_message(node, topic, args.timeout)
            if text is None:
                print(f"TIMEOUT {topic}", flush=True)
                status = 1
                break
            print(f"RECEIVED {topic} {text}", flush=True)
            if step == 0:
                bridge.remove(handle)  # the other bridges (none here) keep running
                print(f"REMOVED {topic}", flush=True)
    except KeyboardInterrupt:
        print("INTERRUPTED", flush=True)
        status = 130
    finally:
        bridge.close()
        executor.shutdown(timeout_sec=1.0)
        node.destroy_node()
        rclpy.try_shutdown()
        spinner.join(timeout=2.0)
    print("DONE", flush=True)
    return status


if __name__ == "__main__":
    sys.exit(main())

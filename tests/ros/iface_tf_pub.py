"""Publish TFMessages from a process of its own, for tests/ros/test_interfaces.py.

usage: iface_tf_pub.py TOPIC TOKEN

Waits (at most 20 s) for a subscriber, then publishes up to 50 messages at 10 Hz whose
frame ids carry TOKEN, and exits; the test stops it earlier once it has received one.
Exit status 2 means no subscriber ever matched.
"""

from __future__ import annotations

import sys
import time
from typing import Any

import rclpy
from geometry_msgs.msg import TransformStamped
from rclpy.utilities import try_shutdown
from tf2_msgs.msg import TFMessage

MATCH_TIMEOUT_S = 20.0
MAX_MESSAGES = 50
PERIOD_S = 0.1


def make_message(token: str, index: int) -> Any:
    """Two transforms with values a test can recognise (and the message index)."""
    first = TransformStamped()
    first.header.stamp.sec = 1_700_000_000
    first.header.stamp.nanosec = index
    first.header.frame_id = f"world_{token}"
    first.child_frame_id = f"base_{token}"
    first.transform.translation.x = 1.5
    first.transform.translation.y = -2.25
    first.transform.translation.z = 3.125
    first.transform.rotation.w = 1.0
    second = TransformStamped()
    second.header.frame_id = f"base_{token}"
    second.child_frame_id = f"camera_{token}"
    second.transform.rotation.x = 0.5
    second.transform.rotation.y = 0.5
    second.transform.rotation.z = 0.5
    second.transform.rotation.w = 0.5
    return TFMessage(transforms=[first, second])


def main(topic: str, token: str) -> int:
    rclpy.init()
    try:
        node = rclpy.create_node(f"iface_tf_pub_{token}")
        publisher = node.create_publisher(TFMessage, topic, 10)
        deadline = time.monotonic() + MATCH_TIMEOUT_S
        while publisher.get_subscription_count() == 0:
            if time.monotonic() > deadline:
                return 2
            time.sleep(0.05)
        for index in range(MAX_MESSAGES):
            publisher.publish(make_message(token, index))
            time.sleep(PERIOD_S)
        return 0
    finally:
        try_shutdown()


if __name__ == "__main__":
    sys.exit(main(sys.argv[1], sys.argv[2]))

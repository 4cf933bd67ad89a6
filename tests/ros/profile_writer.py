"""One side of a reliable topic in a process of its own, for tests/ros/test_fastdds_profile.py.

usage: profile_writer.py publish TOPIC COUNT
       profile_writer.py subscribe TOPIC SECONDS
(with the repository on PYTHONPATH, for ``testing``)

``publish`` waits (at most 20 s) for a subscriber, publishes COUNT strings at about 1 kHz
(reliable, volatile, depth 10, as the bridge's publishers are), waits for the subscriber to
acknowledge them all, and prints ``WAKES <n> SENT <count>``: how often this process's Fast DDS
event threads (``dds.ev.<n>``) went to sleep and were woken meanwhile (their voluntary context
switches). Exit status 2: no subscriber matched; 3: not all were acknowledged within 5 s.
``subscribe`` takes the topic for SECONDS.
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import rclpy
from rclpy.duration import Duration
from rclpy.utilities import try_shutdown
from std_msgs.msg import String

from ros_gz_bridge_py.ros.runtime import DDS_EVENT_THREAD_PREFIX
from testing.polling import wait_until

MATCH_TIMEOUT_S = 20.0
PERIOD_S = 0.001
ACK_TIMEOUT_S = 5.0


def event_thread_wakes() -> int:
    """The voluntary context switches of this process's Fast DDS event threads."""
    total = 0
    for task in Path("/proc/self/task").iterdir():
        if (task / "comm").read_text().strip().startswith(DDS_EVENT_THREAD_PREFIX):
            for line in (task / "status").read_text().splitlines():
                if line.startswith("voluntary_ctxt_switches:"):
                    total += int(line.split()[1])
    return total


def publish(topic: str, count: int) -> int:
    node = rclpy.create_node("profile_writer")
    publisher = node.create_publisher(String, topic, 10)
    if not wait_until(lambda: publisher.get_subscription_count() > 0, MATCH_TIMEOUT_S):
        return 2
    time.sleep(0.5)  # past the match's own discovery traffic
    before = event_thread_wakes()
    message = String()
    start = time.monotonic()
    for index in range(count):
        message.data = f"sample {index}"
        publisher.publish(message)
        time.sleep(max(0.0, start + (index + 1) * PERIOD_S - time.monotonic()))
    if not publisher.wait_for_all_acked(Duration(seconds=ACK_TIMEOUT_S)):
        return 3
    print(f"WAKES {event_thread_wakes() - before} SENT {count}", flush=True)
    return 0


def subscribe(topic: str, seconds: float) -> int:
    node = rclpy.create_node("profile_reader")
    node.create_subscription(String, topic, lambda _: None, 10)
    deadline = time.monotonic() + seconds
    while time.monotonic() < deadline:
        rclpy.spin_once(node, timeout_sec=0.1)
    return 0


def main() -> int:
    mode, topic, amount = sys.argv[1:4]
    rclpy.init()
    try:
        if mode == "publish":
            return publish(topic, int(amount))
        return subscribe(topic, float(amount))
    finally:
        try_shutdown()


if __name__ == "__main__":
    sys.exit(main())

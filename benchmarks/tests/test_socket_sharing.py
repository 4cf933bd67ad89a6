"""The socket sharing benchmark's reader on real ZeroMQ sockets, and its report's arithmetic."""

from __future__ import annotations

import argparse
import time

import zmq

from benchmarks.socket_sharing import Figures, Reader, section

TOPICS = ["@p@/robot_1/odom", "@p@/robot_1/imu"]


def _publish_until_read(shared: bool) -> tuple[int, int]:
    """Messages the reader took of 50 per subscribed topic (and 50 of a topic it does not
    subscribe, sent first), once the publisher holds every subscription; and how many sockets
    it read."""
    context = zmq.Context(1)
    pub = context.socket(zmq.XPUB)  # it tells each new subscription
    pub.bind("tcp://127.0.0.1:*")
    reader = Reader(pub.getsockopt_string(zmq.LAST_ENDPOINT), TOPICS, shared=shared)
    reader.start()
    try:
        subscribed: set[str] = set()
        while not set(TOPICS) <= subscribed:
            assert pub.poll(10_000), f"subscriptions after 10 s: {sorted(subscribed)}"
            subscription = pub.recv()
            if subscription[:1] == b"\x01":
                subscribed.add(subscription[1:].decode())
        for topic in ["@p@/robot_2/odom", *TOPICS]:
            for _ in range(50):
                pub.send_multipart([topic.encode(), b"sender", b"payload", b"type"])
        deadline = time.monotonic() + 10
        while reader.messages < 50 * len(TOPICS) and time.monotonic() < deadline:
            time.sleep(0.01)
        return reader.messages, len(reader.sockets)
    finally:
        reader.close()
        pub.close(0)
        context.term()


def test_a_socket_per_topic_and_one_shared_both_read_every_subscribed_message() -> None:
    assert _publish_until_read(shared=False) == (100, 2)
    assert _publish_until_read(shared=True) == (100, 1)


def test_the_report_gives_each_round_and_the_mean_saved_per_message() -> None:
    calls = {"reader": {"getpid": 3.0, "poll": 2.5}, "I/O": {"recvfrom": 0.9}}
    rounds = [
        Figures("per topic", 4500.0, 50.0, 1.3, 11.0, 0.28, calls),
        Figures("shared", 4500.0, 41.0, 1.2, 5.0, 0.23, {}),
        Figures("shared", 4500.0, 43.0, 1.2, 6.0, 0.23, {}),
        Figures("per topic", 4500.0, 52.0, 1.3, 12.0, 0.28, {}),
    ]
    args = argparse.Namespace(robots=[10], seconds=15.0, syscall_seconds=8.0, rounds=2)
    text = section({10: rounds}, args, 0.5)
    assert "### 10 robots (31 topics from one simulator process, 4,500 messages" in text
    assert "| 1 | per topic | 4,500 | 50.00 | 1.30 | 11.00 | 0.28 | 5.50 (getpid 3.00" in text
    assert "| 1 | shared | 4,500 | 41.00 | 1.20 | 5.00 | 0.23 | - | - |" in text
    assert "11.50 µs per message with a socket per topic, 5.50 with one shared" in text
    assert "(+6.00 saved)" in text
    assert "the reader 51.00 and 42.00 (+9.00)" in text

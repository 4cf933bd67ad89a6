"""The native loop and one channel's pump, in process (docs/native.md §5): real ZeroMQ sockets
(a PUB that stands for a Gazebo publisher, the SUB the loop reads) and a real rclpy publisher
the pump publishes on. What a reader does in Python (learning the routes of what the loop hands
back) is done here by the test.
"""

from __future__ import annotations

import time
from typing import Any

import pytest
import zmq

from ros_gz_bridge_py.converters.registry import default_registry
from ros_gz_bridge_py.msgs import message_class
from ros_gz_bridge_py.native.channel import program_of
from ros_gz_bridge_py.native.pump import foreign_functions

pytestmark = pytest.mark.ros

TOPIC = b"@/test_partition@/pumped"
TYPE = b"ignition.msgs.StringMsg"
LEGIT = b"legit-sender"
PAYLOAD = message_class("gz.msgs.StringMsg")(data="pumped").SerializeToString()


class Rig:
    """A pump on a loop, reading a SUB socket that a PUB of the test sends to."""

    def __init__(self, native: Any, publisher: Any, *, capacity: int, max_bytes: int) -> None:
        functions = foreign_functions()
        assert functions is not None
        program = program_of(default_registry().get("std_msgs/msg/String", "gz.msgs.StringMsg"))
        self.pump = native.Pump(
            TOPIC, functions, publisher.handle.pointer, {TYPE: program}, capacity, 0.0, max_bytes
        )
        self.loop = native.Loop()
        self.context = zmq.Context()
        self.pub = self.context.socket(zmq.PUB)
        self.pub.setsockopt(zmq.SNDHWM, 0)  # the test's bursts are not to be dropped by ZeroMQ
        port = self.pub.bind_to_random_port("tcp://127.0.0.1")
        self.sub = self.context.socket(zmq.SUB)
        self.sub.setsockopt(zmq.RCVHWM, 0)
        self.sub.setsockopt(zmq.SUBSCRIBE, TOPIC)
        self.sub.connect(f"tcp://127.0.0.1:{port}")
        self.loop.add(self.pump, self.sub.underlying, 0)
        self.handed_senders: list[bytes] = []

    def send(self, sender: bytes, payload: bytes) -> None:
        self.pub.send_multipart([TOPIC, sender, payload, TYPE])

    def connected(self) -> None:
        """Sends until a message arrives (a SUB connects asynchronously); learns its route."""
        deadline = time.monotonic() + 10
        while not self.handed_senders and time.monotonic() < deadline:
            self.send(LEGIT, b"")
            self.turn(50)
        assert self.handed_senders, "the SUB socket never connected"

    def turn(self, timeout_ms: int = 20) -> None:
        """One run of the loop, then what a reader does: learn the route of every message
        handed back as unrouted."""
        _woken, reported = self.loop.run(timeout_ms, [])
        for _pump, _events in reported:
            for item in self.pump.take_handed():
                if item[0] == 0:
                    frames = item[1]
                    self.handed_senders.append(frames[1])
                    self.pump.learn(frames[1], frames[3], True)

    def settle(self) -> None:
        """Runs until nothing more arrives for a while."""
        before = -1
        while self.pump.counts() != before:
            before = self.pump.counts()
            self.turn(100)

    def close(self) -> None:
        self.loop.remove(self.pump)
        self.pub.close(linger=0)
        self.sub.close(linger=0)
        self.context.term()


def test_a_sender_that_changes_every_message_leaves_the_others_routes_alone(
    native: Any, publisher: Any
) -> None:
    """A rogue sender frame per message fills the route table again and again; the publisher
    that keeps sending is never judged by Python again (before: at 1024 routes every route and
    the queue were forgotten)."""
    rig = Rig(native, publisher, capacity=1000, max_bytes=1 << 26)
    try:
        rig.connected()
        for i in range(3000):
            rig.send(f"rogue-{i}".encode(), PAYLOAD)
            if i % 10 == 0:
                rig.send(LEGIT, PAYLOAD)
            if i % 50 == 0:
                rig.turn(0)
        rig.settle()
        assert rig.handed_senders.count(LEGIT) == 1
        assert len(rig.handed_senders) == 3001  # every rogue message judged once, by Python
        received, _limited, published, dropped, _skipped, lost = rig.pump.counts()
        assert (dropped, lost) == (0, 0)
        assert received == published >= 300
    finally:
        rig.close()


def test_the_queue_is_bounded_in_bytes(native: Any, publisher: Any) -> None:
    """Large messages arriving faster than they are published: the oldest are dropped once
    the queue holds ``max_bytes``, however few messages that is (before: 1000 of any size)."""
    size, limit, count = 10_000, 25_000, 200
    rig = Rig(native, publisher, capacity=1000, max_bytes=limit)
    try:
        rig.connected()
        rig.settle()
        before = rig.pump.counts()
        read_before, no_sender = rig.pump.traffic()
        payload = message_class("gz.msgs.StringMsg")(data="x" * size).SerializeToString()
        for _ in range(count):
            rig.send(LEGIT, payload)
        time.sleep(0.5)  # all of them in the SUB socket's queue before the loop reads
        rig.settle()
        received, _limited, published, dropped, _skipped, lost = (
            now - then for now, then in zip(rig.pump.counts(), before, strict=True)
        )
        assert dropped > 0
        assert (received + dropped, lost) == (count, 0)
        assert published == received
        # what the loop's trim after a burst and the drop warning read
        assert no_sender == b""
        assert rig.pump.traffic() == (read_before + count * len(payload), LEGIT)
    finally:
        rig.close()


def test_a_pump_that_was_never_initialised_is_refused(native: Any) -> None:
    blank = native.Pump.__new__(native.Pump)
    with pytest.raises(RuntimeError, match="not initialised"):
        blank.take_handed()
    with pytest.raises(RuntimeError, match="not initialised"):
        blank.learn(b"s", b"t", True)
    with pytest.raises(TypeError, match="initialised Pump"):
        native.Loop().add(blank, 1, 0)


def test_a_payload_above_the_watched_size_is_told(native: Any, publisher: Any) -> None:
    """The reader lowers its socket's receive HWM when payloads grow (transport/zmq/reader.py):
    the pump tells it the largest payload above the size it watches, once, and wakes Python
    for it; nothing is told before a size is watched, or for payloads within it."""
    rig = Rig(native, publisher, capacity=1000, max_bytes=1 << 26)
    try:
        rig.connected()
        payload = message_class("gz.msgs.StringMsg")(data="x" * 5000).SerializeToString()
        rig.send(LEGIT, payload)
        rig.settle()
        assert rig.pump.take_grown() == 0  # nothing watched
        rig.pump.watch(1000)
        rig.send(LEGIT, PAYLOAD)
        rig.settle()
        assert rig.pump.take_grown() == 0  # within the watched size
        larger = message_class("gz.msgs.StringMsg")(data="y" * 8000).SerializeToString()
        for data in (payload, larger, payload):
            rig.send(LEGIT, data)
        _woken, reported = rig.loop.run(2000, [])
        deadline = time.monotonic() + 5
        while not reported and time.monotonic() < deadline:
            _woken, reported = rig.loop.run(100, [])
        assert reported, "the loop did not hand the pump to Python"
        rig.settle()
        assert rig.pump.take_grown() == len(larger)
        assert rig.pump.take_grown() == 0  # told once
        rig.pump.watch(-1)
        rig.send(LEGIT, larger)
        rig.settle()
        assert rig.pump.take_grown() == 0
    finally:
        rig.close()


def _one_run_with_reports(rig: Rig) -> list[Any]:
    """One loop run that reports (waiting for the first message to be read)."""
    deadline = time.monotonic() + 5
    reported: list[Any] = []
    while not reported and time.monotonic() < deadline:
        _woken, reported = rig.loop.run(100, [])
    assert reported, "the loop did not hand the pump to Python"
    return list(rig.pump.take_handed())


def test_a_read_hands_python_at_most_max_bytes_of_unrouted_copies(
    native: Any, publisher: Any
) -> None:
    """Messages of a sender whose route Python has not learned yet are copied to Python; a
    read ends once the copies hold ``max_bytes``, so Python learns the route before more are
    copied (before: a whole read budget, 64 messages of 32 MB were 2 GB, the loop's other
    channels waiting meanwhile)."""
    size, limit, count = 10_000, 25_000, 40
    rig = Rig(native, publisher, capacity=1000, max_bytes=limit)
    try:
        rig.connected()
        rig.settle()
        payload = message_class("gz.msgs.StringMsg")(data="x" * size).SerializeToString()
        for _ in range(count):
            rig.send(b"unknown-sender", payload)
        time.sleep(0.5)  # all of them in the SUB socket's queue before the loop reads
        handed = _one_run_with_reports(rig)
        assert len(handed) == 3  # 3 copies of 10 kB pass 25 kB: the read ends there
        assert all(item[0] == 0 and item[1][2] == payload for item in handed)
        rig.pump.learn(b"unknown-sender", TYPE, True)
        rig.settle()
        received, _limited, published, dropped, _skipped, lost = rig.pump.counts()
        assert lost == 0
        assert received + dropped == count - 3  # the rest went natively once learned
        assert published == received
    finally:
        rig.close()


def test_a_read_ends_at_a_payload_above_the_watched_size(native: Any, publisher: Any) -> None:
    """The reader replaces its socket for a payload above the watched size before more such
    payloads queue in the old one: the read that took it ends there and tells Python."""
    rig = Rig(native, publisher, capacity=1000, max_bytes=1 << 26)
    try:
        rig.connected()
        rig.settle()
        rig.pump.watch(1000)
        larger = message_class("gz.msgs.StringMsg")(data="y" * 8000).SerializeToString()
        taken_before = rig.pump.traffic()[0]
        for _ in range(10):
            rig.send(LEGIT, larger)
        time.sleep(0.5)
        _one_run_with_reports(rig)
        assert rig.pump.take_grown() == len(larger)
        assert rig.pump.traffic()[0] - taken_before == len(larger)  # one read, not ten
        rig.settle()
        assert rig.pump.traffic()[0] - taken_before == 10 * len(larger)
    finally:
        rig.close()

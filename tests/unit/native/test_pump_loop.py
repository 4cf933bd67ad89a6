"""One Gazebo -> ROS channel's pump on a loop, in process (docs/native.md §5), on the rig of
pump_rig.py: real ZeroMQ sockets and a real rclpy publisher.
"""

from __future__ import annotations

import time
from typing import Any

import pytest

from ros_gz_bridge_py.msgs import message_class
from tests.unit.native.loop_fuzz_host import Host
from tests.unit.native.pump_rig import BUDGET, LEGIT, PAYLOAD, TOPIC, TYPE, Rig

pytestmark = pytest.mark.ros


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
        counts = rig.pump.counts()
        assert (counts.dropped, counts.lost) == (0, 0)
        assert counts.received == counts.published >= 300
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
        no_sender = rig.pump.dropped_sender
        payload = message_class("gz.msgs.StringMsg")(data="x" * size).SerializeToString()
        for _ in range(count):
            rig.send(LEGIT, payload)
        time.sleep(0.5)  # all of them in the SUB socket's queue before the loop reads
        rig.settle()
        after = rig.pump.counts()
        received, dropped = after.received - before.received, after.dropped - before.dropped
        assert dropped > 0
        assert (received + dropped, after.lost - before.lost) == (count, 0)
        assert after.published - before.published == received
        # what the loop's trim after a burst and the drop warning read
        assert no_sender == b""
        assert after.bytes_read == before.bytes_read + count * len(payload)
        assert rig.pump.dropped_sender == LEGIT
    finally:
        rig.close()


def test_a_pump_that_was_never_initialised_is_refused(native: Any) -> None:
    blank = native.Pump.__new__(native.Pump)
    with pytest.raises(RuntimeError, match="not initialised"):
        blank.take_handed()
    with pytest.raises(RuntimeError, match="not initialised"):
        blank.learn(b"s", b"t", True)
    with pytest.raises(RuntimeError, match="not initialised"):
        blank.read_from(1, 0)
    with pytest.raises(TypeError, match="initialised Pump"):
        native.Loop(*BUDGET).add(blank)


def test_a_payload_above_the_watched_size_is_told(native: Any, publisher: Any) -> None:
    """The reader lowers its socket's receive HWM when payloads grow
    (transport/zmq/reader.py): each hand-over tells it the largest payload above the size
    it watches since the last, and the loop reports the pump for it; nothing is told before a
    size is watched, or for payloads within it."""
    rig = Rig(native, publisher, capacity=1000, max_bytes=1 << 26)
    try:
        rig.connected()
        payload = message_class("gz.msgs.StringMsg")(data="x" * 5000).SerializeToString()
        rig.send(LEGIT, payload)
        rig.settle()
        assert rig.grown == []  # nothing watched
        rig.pump.watch(1000)
        rig.send(LEGIT, PAYLOAD)
        rig.settle()
        assert rig.grown == []  # within the watched size
        larger = message_class("gz.msgs.StringMsg")(data="y" * 8000).SerializeToString()
        for data in (payload, larger, payload):
            rig.send(LEGIT, data)
        deadline = time.monotonic() + 5
        while not rig.turn(100) and time.monotonic() < deadline:
            pass
        rig.settle()
        told = list(rig.grown)  # the largest since the last hand-over, each time
        assert max(told) == len(larger), told
        assert told.count(len(larger)) == 1, told
        assert set(told) <= {len(payload), len(larger)}
        rig.pump.watch(-1)
        rig.send(LEGIT, larger)
        rig.settle()
        assert rig.grown == told
    finally:
        rig.close()


def _one_run_with_reports(rig: Rig) -> Any:
    """One loop run that reports (waiting for the first message to be read): its hand-over."""
    deadline = time.monotonic() + 5
    reported: list[Any] = []
    while not reported and time.monotonic() < deadline:
        _woken, reported = rig.loop.run(100, [])
    assert reported, "the loop did not hand the pump to Python"
    return rig.pump.take_handed()


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
        before = rig.pump.counts()
        payload = message_class("gz.msgs.StringMsg")(data="x" * size).SerializeToString()
        for _ in range(count):
            rig.send(b"unknown-sender", payload)
        time.sleep(0.5)  # all of them in the SUB socket's queue before the loop reads
        handover = _one_run_with_reports(rig)
        assert len(handover.unrouted) == 3  # 3 copies of 10 kB pass 25 kB: the read ends there
        assert all(frames[2] == payload for frames in handover.unrouted)
        rig.pump.learn(b"unknown-sender", TYPE, True)
        rig.settle()
        after = rig.pump.counts()
        received, dropped = after.received - before.received, after.dropped - before.dropped
        assert after.lost == 0
        assert received + dropped == count - 3  # the rest went natively once learned
        assert after.published - before.published == received
    finally:
        rig.close()


def test_a_read_ends_at_a_payload_above_the_watched_size(native: Any, publisher: Any) -> None:
    """The socket owner replaces its socket for a payload above the watched size before more
    such payloads queue in the old one: the read that took it ends there and tells Python."""
    rig = Rig(native, publisher, capacity=1000, max_bytes=1 << 26)
    try:
        rig.connected()
        rig.settle()
        rig.pump.watch(1000)
        larger = message_class("gz.msgs.StringMsg")(data="y" * 8000).SerializeToString()
        read_before = rig.pump.counts().bytes_read
        for _ in range(10):
            rig.send(LEGIT, larger)
        time.sleep(0.5)
        assert _one_run_with_reports(rig).grown == len(larger)
        assert rig.pump.counts().bytes_read - read_before == len(larger)  # one read, not ten
        rig.settle()
        assert rig.pump.counts().bytes_read - read_before == 10 * len(larger)
    finally:
        rig.close()


def test_a_topic_the_channel_prefixes_leaves_the_channels_route_alone(
    native: Any, publisher: Any
) -> None:
    """ZeroMQ subscribes by prefix: a topic the channel's name prefixes (``/x/pose_static``
    beside ``/x/pose``), sent by the channel's own publisher with the channel's type, comes
    through the channel's socket. The real reader judges it not the channel's; that verdict
    used to be taught to the pump as the route of (sender, type), and the pump skipped the
    channel's own messages of that publisher from then on, without a word (found by
    fuzz/loop_fuzz.c)."""
    host = Host(TOPIC.decode())
    rig = Rig(native, publisher, capacity=1000, max_bytes=1 << 26, judge=host.judge)
    host.reset(rig.pump, [TYPE])
    sender = b"tcp://127.0.0.1:40001"
    try:
        rig.connected()
        # the other topic's message, then the channel's: each judged by the reader
        for topic in (TOPIC + b"_static", TOPIC):
            handed, deadline = len(rig.handed_senders), time.monotonic() + 10
            rig.pub.send_multipart([topic, sender, PAYLOAD, TYPE])
            while len(rig.handed_senders) == handed and time.monotonic() < deadline:
                rig.turn(50)
            assert len(rig.handed_senders) == handed + 1, f"{topic!r} was not handed back"
        before = rig.pump.counts()
        for _ in range(20):
            rig.pub.send_multipart([TOPIC, sender, PAYLOAD, TYPE])
        rig.settle()
        after = rig.pump.counts()
        assert after.skipped == before.skipped == 0
        assert after.published - before.published == 20
        assert rig.handed_senders.count(sender) == 2
    finally:
        rig.close()
        host.close()


def test_messages_waiting_when_the_socket_is_replaced_are_counted_dropped(
    native: Any, publisher: Any
) -> None:
    """``forget`` (the socket owner replaces the socket: a new receive mark, or a topic leaving
    the shared socket) lets go of what the old socket's reads left waiting; those count as
    dropped, not vanish (before: uncounted). The routes stay: a sender known before is not
    judged again, its next messages go natively (before: each sender's first message on the
    new socket was copied for Python again, 32 MB a piece in a flood of padded frames)."""
    rig = Rig(native, publisher, capacity=1000, max_bytes=1 << 26)
    try:
        rig.connected()
        rig.settle()
        before = rig.pump.counts()
        for _ in range(3):
            rig.send(b"unknown-sender", PAYLOAD)  # copies for Python, waiting to be taken
        time.sleep(0.2)
        deadline = time.monotonic() + 5
        while rig.pump.counts().received == before.received and time.monotonic() < deadline:
            rig.loop.run(100, [])  # read, but nothing taken from the hand-over
        assert rig.loop.remove(rig.pump)
        rig.pump.forget()
        after = rig.pump.counts()
        assert after.dropped - before.dropped == 3
        assert rig.pump.take_handed().unrouted == []
        rig.loop.add(rig.pump)
        judged = rig.handed_senders.count(LEGIT)
        for _ in range(5):
            rig.send(LEGIT, PAYLOAD)
        rig.settle()
        assert rig.pump.counts().published - after.published == 5
        assert rig.handed_senders.count(LEGIT) == judged == 1
    finally:
        rig.close()

"""A loop at its counts (native/loop.py, docs/native.md §5 item 7): only the members that read
something are asked for their bytes, and a member's burst of large messages is still trimmed
once it is over.

A loop of its own (``NativeLoop``, with its thread), real C pumps publishing on a real rclpy
publisher, real ZeroMQ sockets; each member's Python share is the test's: it learns the route
of what the loop hands back, as a socket owner does, and counts how often the loop asks for its
bytes.
"""

from __future__ import annotations

import threading
import time
from typing import Any

import pytest
import zmq

from ros_gz_bridge_py.converters.registry import default_registry
from ros_gz_bridge_py.msgs import message_class
from ros_gz_bridge_py.native.abi import zmq_functions
from ros_gz_bridge_py.native.channel import program_of
from ros_gz_bridge_py.native.loop import COUNT_EVERY, LOOP_TRIM_AFTER, NativeLoop

pytestmark = pytest.mark.ros

#: Upper bound of every wait for something that should happen.
WAIT = 10.0
#: Channels on the loop; the first one gets the burst.
CHANNELS = 20
TYPE = b"ignition.msgs.StringMsg"
SMALL = message_class("gz.msgs.StringMsg")(data="hello").SerializeToString()
#: Four of these are a burst (over LOOP_TRIM_AFTER).
LARGE = message_class("gz.msgs.StringMsg")(data="x" * (LOOP_TRIM_AFTER // 3)).SerializeToString()


class Channel:
    """One pump on the loop, reading a SUB socket that the test's PUB sends to."""

    def __init__(
        self, native: Any, publisher: Any, context: zmq.Context[Any], port: int, i: int
    ) -> None:
        functions = zmq_functions()
        program = program_of(default_registry().get("std_msgs/msg/String", "gz.msgs.StringMsg"))
        assert functions is not None
        assert program is not None
        self.topic = f"@/test@/counted_{i}".encode()
        self.pump = native.Pump(
            self.topic, functions, publisher.handle.pointer, {TYPE: program}, 1000, 0.0, 1 << 28
        )
        self.sub = context.socket(zmq.SUB)
        self.sub.setsockopt(zmq.SUBSCRIBE, self.topic)
        self.sub.connect(f"tcp://127.0.0.1:{port}")
        self.pump.read_from(self.sub.underlying, 0)
        self.asked = 0  # how often the loop asked for the bytes read
        self.learned = threading.Event()

    @property
    def bytes_read(self) -> int:
        self.asked += 1
        read: int = self.pump.counts().bytes_read
        return read

    def turn(self, *, handed: bool, monitor: bool, broken: bool) -> float | None:
        """What a socket owner does: learn the route of every message handed back as
        unrouted."""
        del monitor, broken
        for frames in self.pump.take_handed().unrouted if handed else ():
            self.pump.learn(frames[1], frames[3], True)
            self.learned.set()
        return None


def _settled(channels: list[Channel]) -> list[int]:
    """How often each channel was asked, once two counts asked none (the messages sent
    while the sockets connected have all been read and counted)."""
    deadline = time.monotonic() + WAIT
    asked = [channel.asked for channel in channels]
    while True:
        time.sleep(2 * COUNT_EVERY)
        now = [channel.asked for channel in channels]
        if now == asked:
            return now
        assert time.monotonic() < deadline, "the channels never came to rest"
        asked = now


def test_only_channels_that_read_are_counted_and_a_burst_is_trimmed(
    native: Any, publisher: Any
) -> None:
    """20 channels, one of which reads a burst of 4 large messages: the 19 at rest are never
    asked for their bytes again (before: every channel at every count), and
    the burst is trimmed once the channel is quiet."""
    trims: list[float] = []
    trimmed = threading.Event()

    def trim() -> None:
        trims.append(time.monotonic())
        trimmed.set()

    loop = NativeLoop(native, "test-native", trim=trim)
    context: zmq.Context[Any] = zmq.Context()
    pub = context.socket(zmq.PUB)
    pub.setsockopt(zmq.SNDHWM, 0)
    port = pub.bind_to_random_port("tcp://127.0.0.1")
    channels = [Channel(native, publisher, context, port, i) for i in range(CHANNELS)]
    try:
        for channel in channels:
            loop.attach(channel)
        deadline = time.monotonic() + WAIT
        while not all(channel.learned.is_set() for channel in channels):
            assert time.monotonic() < deadline, "a SUB socket never connected"
            for channel in channels:
                if not channel.learned.is_set():
                    pub.send_multipart([channel.topic, b"sender", SMALL, TYPE])
            time.sleep(0.05)
        asked = _settled(channels)
        burst = channels[0]
        for _ in range(4):
            pub.send_multipart([burst.topic, b"sender", LARGE, TYPE])
        assert trimmed.wait(WAIT), "the burst was never trimmed"
        time.sleep(2 * COUNT_EVERY)  # more counts at rest
        assert [channel.asked for channel in channels[1:]] == asked[1:]
        assert burst.asked > asked[0]
        assert len(trims) == 1
        assert burst.pump.counts().bytes_read >= 4 * len(LARGE)
    finally:
        for channel in channels:
            loop.detach(channel)
            channel.sub.close(linger=0)
        pub.close(linger=0)
        context.term()

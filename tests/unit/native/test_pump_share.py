"""One SUB socket for several topics (``Pump.share``, docs/native.md §5): a reader pump reads
the socket and each message goes to the queue of its topic's pump, which publishes it on its
own publisher; real ZeroMQ sockets and a real rclpy publisher, in process.
"""

from __future__ import annotations

import time
from typing import Any

import pytest
import zmq

from ros_gz_bridge_py.converters.registry import default_registry
from ros_gz_bridge_py.native.abi import zmq_functions
from ros_gz_bridge_py.native.channel import program_of
from tests.unit.native.pump_rig import BUDGET, PAYLOAD, TYPE

pytestmark = pytest.mark.ros

ODOM, CLOCK = b"@/p@/robot/odom", b"@/p@/clock"
#: A topic ZeroMQ lets through by prefix (the socket subscribes to ODOM): nobody's.
PREFIXED = ODOM + b"_static"


class SharedRig:
    """A reader pump (no publisher, no programs) on a loop, reading for two peer pumps."""

    def __init__(self, native: Any, publisher: Any) -> None:
        functions = zmq_functions()
        program = program_of(default_registry().get("std_msgs/msg/String", "gz.msgs.StringMsg"))
        assert functions is not None
        assert program is not None

        def pump(topic: bytes, address: int, programs: dict[bytes, Any]) -> Any:
            return native.Pump(topic, functions, address, programs, 1000, 0.0, 1 << 24)

        self.reader = pump(b"", 0, {})
        self.peers = {t: pump(t, publisher.handle.pointer, {TYPE: program}) for t in (ODOM, CLOCK)}
        self.reader.share(list(self.peers.values()))
        self.context = zmq.Context()
        self.pub = self.context.socket(zmq.PUB)
        self.pub.setsockopt(zmq.SNDHWM, 0)
        port = self.pub.bind_to_random_port("tcp://127.0.0.1")
        self.sub = self.context.socket(zmq.SUB)
        self.sub.setsockopt(zmq.RCVHWM, 0)
        for topic in self.peers:
            self.sub.setsockopt(zmq.SUBSCRIBE, topic)
        self.sub.connect(f"tcp://127.0.0.1:{port}")
        self.reader.read_from(self.sub.underlying, 0)
        self.loop = native.Loop(*BUDGET)
        self.loop.add(self.reader)
        #: The frames each peer handed back (what its socket owner judges), by topic.
        self.handed: dict[bytes, list[list[bytes]]] = {topic: [] for topic in self.peers}

    def send(self, topic: bytes, sender: bytes = b"gz-sender") -> None:
        self.pub.send_multipart([topic, sender, PAYLOAD, TYPE])

    def turn(self, timeout_ms: int = 20) -> None:
        """A run of the loop, then what the socket owners do: each peer's hand-over judged,
        its route learned."""
        _woken, reported = self.loop.run(timeout_ms, [])
        if not reported:
            return
        assert self.reader.take_handed().unrouted == []
        for topic, peer in self.peers.items():
            for frames in peer.take_handed().unrouted:
                self.handed[topic].append(frames)
                peer.learn(frames[1], frames[3], True)

    def until(self, done: Any, seconds: float = 10.0) -> None:
        deadline = time.monotonic() + seconds
        while not done() and time.monotonic() < deadline:
            self.turn()
        assert done()

    def close(self) -> None:
        self.loop.remove(self.reader)
        self.pub.close(linger=0)
        self.sub.close(linger=0)
        self.context.term()


def test_each_topic_goes_to_its_own_pump(native: Any, publisher: Any) -> None:
    rig = SharedRig(native, publisher)
    try:

        def routed() -> bool:
            rig.send(ODOM)
            rig.send(CLOCK)
            return all(rig.handed.values())

        rig.until(routed)
        # the first frames of each topic, handed until its route was learned (more than one
        # when the loop read a second before the socket owner learned from the first)
        judged = {topic: len(frames) for topic, frames in rig.handed.items()}
        for _ in range(300):
            rig.send(ODOM)
            rig.send(PREFIXED)
        for _ in range(100):
            rig.send(CLOCK)
        odom, clock = rig.peers[ODOM], rig.peers[CLOCK]
        rig.until(
            lambda: (
                odom.counts().published >= 300
                and clock.counts().published >= 100
                and rig.reader.counts().skipped >= 300
            )
        )
        # each topic's frames were judged by its own socket owner, and none once its route
        # was learned: the routes hold
        assert {topic: len(frames) for topic, frames in rig.handed.items()} == judged
        assert all(frames[0] == topic for topic, each in rig.handed.items() for frames in each)
        for topic, pump in ((ODOM, odom), (CLOCK, clock)):
            counts = pump.counts()
            assert counts.received == counts.published == counts.taken - judged[topic]
            assert (counts.dropped, counts.lost, counts.skipped) == (0, 0, 0)
        reader = rig.reader.counts()
        assert reader.skipped == 300  # the prefixed topic: nobody's, not handed to Python
        assert reader.taken == odom.counts().taken + clock.counts().taken + 300
        assert reader.published == reader.received == 0
    finally:
        rig.close()


def test_peers_are_refused_what_would_let_two_read_one_queue(native: Any, publisher: Any) -> None:
    rig = SharedRig(native, publisher)
    try:
        odom = rig.peers[ODOM]
        with pytest.raises(RuntimeError, match="another reads for it"):
            odom.read_from(rig.sub.underlying, 0)  # a peer reads nothing itself
        with pytest.raises(RuntimeError, match="loop runs the pump"):
            rig.reader.share([])  # only out of its loop
        rig.loop.remove(rig.reader)
        with pytest.raises(ValueError, match="read once"):
            rig.reader.share([odom, odom])
        with pytest.raises(ValueError, match="this pump"):
            rig.reader.share([rig.reader])
        with pytest.raises(TypeError, match="Pumps"):
            rig.reader.share([object()])
        rig.reader.share([rig.peers[CLOCK]])  # the odometry pump is let go
        odom.forget()
        odom.read_from(rig.sub.underlying, 0)
        rig.loop.add(rig.reader)
    finally:
        rig.close()
    with pytest.raises(ValueError, match="out of range"):  # a reader only publishes nothing
        native.Pump(b"t", zmq_functions(), 0, {TYPE: None}, 10, 0.0, 10)

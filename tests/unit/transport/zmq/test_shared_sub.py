"""The socket the native channels of small messages share (shared_sub.py), in process: a real
SUB socket and a real PUB standing for a Gazebo publisher; the topics' readers and the native
loop are the test's, since what is checked here is the socket's own bookkeeping (each address
connected once for all its topics, left when its last topic leaves, what waits read before a
disconnect and told to its topic, a refusal told to every topic there). The bridge's own use
of it against a C++ Gazebo peer: tests/bridge/test_native_shared_loop.py.
"""

from __future__ import annotations

from collections.abc import Iterator
from typing import Any

import pytest
import zmq

from ros_gz_bridge_py.transport.api import NativeHost
from ros_gz_bridge_py.transport.settings import TransportSettings
from ros_gz_bridge_py.transport.zmq.shared_sub import SharedSub
from ros_gz_bridge_py.transport.zmq.wire import Frame
from testing.polling import wait_until


class Reader:
    """A topic's reader (shared_sub.py TopicReader): what the socket tells it, kept."""

    def __init__(self, topic: str) -> None:
        self.topic_frame = topic.encode()
        self.taken: list[list[Frame]] = []
        self.refusals: list[str] = []
        self.forwarded: list[tuple[str, str]] = []

    def take(self, frames: list[Frame]) -> None:
        self.taken.append(frames)

    def refused(self, address: str) -> None:
        self.refusals.append(address)

    def connect(self, address: str) -> None:
        self.forwarded.append(("connect", address))

    def leave(self, address: str) -> None:
        self.forwarded.append(("leave", address))

    def native_turn(
        self, unrouted: list[list[Any]], *, monitor: bool, broken: bool, grown: int = 0
    ) -> float | None:
        """The socket's loop turns the topic's share: nothing of it is checked here."""
        return None


class Loop:
    """The native loop's side: a socket reader that the test turns by hand."""

    def __init__(self) -> None:
        self.host: NativeHost | None = None
        self.closed = False

    def socket_reader(self, sock: int, monitor: int, host: NativeHost) -> Loop:
        assert sock
        assert monitor
        self.host = host
        return self

    def attach_shared(self, reader: Any, host: NativeHost) -> None:
        assert reader is self

    def wake(self) -> None:
        """The test turns the host itself."""

    def close(self) -> None:
        self.closed = True


@pytest.fixture
def context() -> Iterator[Any]:
    context = zmq.Context()
    yield context
    context.destroy(linger=0)


def shared_sub(context: Any) -> tuple[SharedSub, Loop]:
    loop = Loop()
    settings = TransportSettings(partition="p")
    return SharedSub(context, settings, lambda *_: None, loop), loop  # type: ignore[arg-type]


def turn(shared: SharedSub) -> None:
    shared.native_turn([], monitor=True, broken=False)


def test_an_address_is_connected_once_and_left_with_its_last_topic(context: Any) -> None:
    shared, loop = shared_sub(context)
    odom, imu = Reader("@/p@/odom"), Reader("@/p@/imu")
    address = "tcp://127.0.0.1:5"
    for reader in (odom, imu):
        shared.add(reader, loop)  # type: ignore[arg-type]
        shared.connect(address, reader)
    turn(shared)
    assert shared.connections.connected == {address}
    assert shared.addresses(odom) == shared.addresses(imu) == [address]
    shared.leave(address, odom)
    turn(shared)
    assert shared.connections.next_deadline() is None  # imu still has a publisher there
    shared.remove(imu)
    turn(shared)
    deadline = shared.connections.next_deadline()
    assert deadline is not None  # left a moment later (what was sent last still arrives)
    assert wait_until(lambda: shared.native_turn([], monitor=False, broken=False) is None)
    assert shared.connections.connected == set()
    shared.close()
    assert loop.closed


def test_what_the_socket_holds_is_read_for_its_topic_before_a_disconnect(context: Any) -> None:
    """``SubConnections.disconnect`` drains the socket first (connections.py); the shared
    socket's drain gives each message to its topic's reader, and one of a topic no reader
    takes (let through by prefix) to none."""
    pub = context.socket(zmq.PUB)
    port = pub.bind_to_random_port("tcp://127.0.0.1")
    address = f"tcp://127.0.0.1:{port}"
    shared, loop = shared_sub(context)
    odom, other = Reader("@/p@/odom"), Reader("@/p@/other")
    for reader in (odom, other):
        shared.add(reader, loop)  # type: ignore[arg-type]
        shared.connect(address, reader)
    turn(shared)

    def arrived() -> bool:  # the subscription is up once a message waits
        pub.send_multipart([b"@/p@/odom", b"sender", b"payload", b"gz.msgs.Odometry"])
        return bool(shared.sock.getsockopt(zmq.EVENTS) & zmq.POLLIN)

    assert wait_until(arrived)
    pub.send_multipart([b"@/p@/odom_static", b"sender", b"payload", b"gz.msgs.Odometry"])
    pub.send_multipart([b"@/p@/odom", b"sender", b"last", b"gz.msgs.Odometry"])

    def drained_to_the_last() -> bool:  # one connection: the prefixed one came before it
        shared._drain()
        return any(bytes(frames[2]) == b"last" for frames in odom.taken)

    assert wait_until(drained_to_the_last)
    assert {bytes(frames[0]) for frames in odom.taken} == {b"@/p@/odom"}
    assert other.taken == []
    shared.connections.disconnect(address)
    assert shared.connections.connected == set()
    shared.close()
    pub.close(linger=0)


def test_a_refusal_is_told_to_every_topic_at_the_address(context: Any) -> None:
    shared, loop = shared_sub(context)
    odom, imu, elsewhere = Reader("@/p@/odom"), Reader("@/p@/imu"), Reader("@/p@/far")
    for reader, address in ((odom, "tcp://127.0.0.1:5"), (imu, "tcp://127.0.0.1:5"),
                            (elsewhere, "tcp://127.0.0.1:6")):  # fmt: skip
        shared.add(reader, loop)  # type: ignore[arg-type]
        shared.connect(address, reader)
    turn(shared)
    shared._refused("tcp://127.0.0.1:5")
    assert (odom.refusals, imu.refusals, elsewhere.refusals) == (
        ["tcp://127.0.0.1:5"],
        ["tcp://127.0.0.1:5"],
        [],
    )
    shared.close()


def test_a_topic_that_moved_meanwhile_gets_its_addresses_itself(context: Any) -> None:
    """A connect or leave posted before the topic left the shared socket (for a socket of its
    own) reaches the topic's reader, which connects its own socket."""
    shared, loop = shared_sub(context)
    odom = Reader("@/p@/odom")
    shared.add(odom, loop)  # type: ignore[arg-type]
    turn(shared)
    shared.remove(odom)
    shared.connect("tcp://127.0.0.1:5", odom)
    shared.leave("tcp://127.0.0.1:6", odom)
    turn(shared)
    assert odom.forwarded == [("connect", "tcp://127.0.0.1:5"), ("leave", "tcp://127.0.0.1:6")]
    assert shared.connections.connected == set()
    shared.close()


def test_a_topic_is_claimed_once_until_its_channel_leaves(context: Any) -> None:
    """A second channel of one Gazebo topic (a fan-out to two ROS topics) is told to read a
    socket of its own; once the first leaves, the topic may be claimed again."""
    shared, loop = shared_sub(context)
    first, second = Reader("@/p@/pose"), Reader("@/p@/pose")
    assert shared.claim(first.topic_frame)
    assert not shared.claim(second.topic_frame)
    assert shared.claim(b"@/p@/odom")
    shared.add(first, loop)  # type: ignore[arg-type]
    shared.remove(first)
    assert shared.claim(second.topic_frame)
    shared.close()


def test_a_channel_the_loop_refuses_leaves_its_claim(context: Any) -> None:
    shared, loop = shared_sub(context)
    reader = Reader("@/p@/pose")

    def refuse(_reader: Any, _host: NativeHost) -> None:
        msg = "refused"
        raise ValueError(msg)

    loop.attach_shared = refuse  # type: ignore[method-assign,assignment]
    assert shared.claim(reader.topic_frame)
    with pytest.raises(ValueError, match="refused"):
        shared.add(reader, loop)  # type: ignore[arg-type]
    assert shared.claim(reader.topic_frame)
    shared.close()

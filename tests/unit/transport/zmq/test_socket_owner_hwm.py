"""A topic's socket owner (socket_owner.py) keeps libzmq's queue in front of its reader's within
the bytes bound: when a payload is large enough that RCVHWM messages of its size would pass
``max_queued_bytes``, the SUB socket's RCVHWM is lowered (``hwm.py``) and its connections made
anew, so that the publisher keeps being heard: libzmq 4.3.5 applies a lowered HWM to the open
connections too, and these stall for good (the first test shows it on raw sockets; the owner
must not be caught by it). Driven here by a reader with its own thread."""

from __future__ import annotations

import threading
import time
from collections.abc import Iterator
from typing import Any

import pytest
import zmq

from ros_gz_bridge_py.transport.api import MessageInfo, Rejection
from ros_gz_bridge_py.transport.settings import TransportSettings
from ros_gz_bridge_py.transport.zmq.hwm import hwm_for_bytes
from ros_gz_bridge_py.transport.zmq.reader import SubscriptionReader
from ros_gz_bridge_py.transport.zmq.socket_owner import Topic

FQN = "@/reader_hwm@/big"
TYPE = b"gz.msgs.StringMsg"
SENDER = b"tcp://127.0.0.1:1"
LIMIT = 10_000_000


def _received(sub: Any, timeout: float) -> int:
    count = 0
    while sub.poll(int(timeout * 1000)):
        sub.recv()
        count += 1
        timeout = 0.2
    return count


def test_a_hwm_lowered_on_an_open_connection_stalls_it() -> None:
    """Why the reader connects anew: the libzmq behaviour it works around, on raw sockets
    (if a libzmq release fixes it, this test says so, and the reconnection can go)."""
    context = zmq.Context()
    try:
        pub = context.socket(zmq.PUB)
        port = pub.bind_to_random_port("tcp://127.0.0.1")
        sub = context.socket(zmq.SUB)
        sub.setsockopt(zmq.SUBSCRIBE, b"")
        sub.connect(f"tcp://127.0.0.1:{port}")
        deadline = time.monotonic() + 10
        while not sub.poll(10) and time.monotonic() < deadline:
            pub.send(b"hello")
        assert _received(sub, 1.0) > 0
        for _ in range(10):
            pub.send(b"before")
        assert _received(sub, 1.0) == 10
        sub.setsockopt(zmq.RCVHWM, 2)
        for _ in range(20):
            pub.send(b"after")
            time.sleep(0.002)
        assert _received(sub, 0.5) == 0
    finally:
        context.destroy(linger=0)


@pytest.fixture(params=[False], ids=["small"])
def reader_and_pub(
    request: pytest.FixtureRequest,
) -> Iterator[tuple[SubscriptionReader, Any, list[bytes]]]:
    settings = TransportSettings.from_env()
    context = zmq.Context()
    pub = context.socket(zmq.PUB)
    port = pub.bind_to_random_port("tcp://127.0.0.1")
    delivered: list[bytes] = []
    rejected: list[tuple[Rejection, str]] = []

    def deliver(payload: Any, _info: MessageInfo) -> None:
        delivered.append(bytes(payload))

    topic = Topic(
        FQN,
        "reader_hwm",
        accepts=lambda _sender, _type: True,
        takes=lambda _type: True,
        reject=lambda reason, detail: rejected.append((reason, detail)),
        settings=settings,
        count=lambda *_args: None,
        max_bytes=LIMIT,
        large_messages=request.param,
    )
    reader = SubscriptionReader(context, topic, deliver=deliver, size=1000)
    reader.connect(f"tcp://127.0.0.1:{port}")
    try:
        yield reader, pub, delivered
        assert not rejected
    finally:
        reader.close()
        pub.close(linger=0)
        context.destroy(linger=0)


def _rcvhwm(reader: SubscriptionReader) -> int:
    """The socket's RCVHWM, read on the reader's own thread."""
    seen: list[int] = []
    done = threading.Event()

    def read() -> None:
        seen.append(int(reader._owner.sock.getsockopt(zmq.RCVHWM)))
        done.set()

    reader._owner.post(read)
    assert done.wait(5)
    return seen[0]


def _send_until(pub: Any, payload: bytes, delivered: list[bytes], timeout: float = 10) -> None:
    """Sends ``payload`` until it is delivered (a SUB connects, and reconnects, on its own)."""
    deadline = time.monotonic() + timeout
    while payload not in delivered and time.monotonic() < deadline:
        pub.send_multipart([FQN.encode(), SENDER, payload, TYPE])
        time.sleep(0.02)
    assert payload in delivered


def test_the_reader_lowers_its_rcvhwm_and_still_hears_the_publisher(
    reader_and_pub: tuple[SubscriptionReader, Any, list[bytes]],
) -> None:
    reader, pub, delivered = reader_and_pub
    settings = TransportSettings.from_env()
    _send_until(pub, b"small", delivered)
    assert _rcvhwm(reader) == settings.rcvhwm
    for _ in range(50):  # the connection's count of reads lags behind (see above)
        pub.send_multipart([FQN.encode(), SENDER, b"more", TYPE])
    first = reader._owner.sock
    big = b"x" * 300_000
    _send_until(pub, big, delivered)
    # room for twice the payload: 10 MB / 600 kB
    assert _rcvhwm(reader) == hwm_for_bytes(2 * len(big), LIMIT, settings.rcvhwm) == 16
    assert reader._owner.sock is not first  # a new socket, never a lowered HWM on open connections
    _send_until(pub, b"after", delivered)  # the connection made anew carries on
    second = reader._owner.sock
    _send_until(pub, b"y" * 600_000, delivered)  # within the room: the same socket
    assert reader._owner.sock is second
    _send_until(pub, b"z" * 2_000_000, delivered)
    assert _rcvhwm(reader) == 2  # as low as it goes: no more watching
    assert reader._owner.sock is not second
    _send_until(pub, b"last", delivered)


@pytest.mark.parametrize("reader_and_pub", [True], ids=["large"], indirect=True)
def test_a_reader_of_large_messages_is_sized_for_the_largest_from_the_start(
    reader_and_pub: tuple[SubscriptionReader, Any, list[bytes]],
) -> None:
    """Images and point clouds: the receive HWM is for the largest message taken, before any
    came, so a camera's first frames do not make the reader connect anew."""
    reader, pub, delivered = reader_and_pub
    settings = TransportSettings.from_env()
    expected = hwm_for_bytes(settings.max_message_size, LIMIT, settings.rcvhwm)
    assert expected == 2
    _send_until(pub, b"small", delivered)
    sock = reader._owner.sock
    assert _rcvhwm(reader) == expected
    _send_until(pub, b"z" * 600_000, delivered)
    assert reader._owner.sock is sock  # the same socket: nothing to lower

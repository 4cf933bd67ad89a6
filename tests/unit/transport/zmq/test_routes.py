"""The shared SUB socket's router hands one received frame to every subscription that takes it,
read-only: a writable payload is a callback's alone (``transport/api.py`` ``Callback``), and
the bulk path writes its CDR into one it owns."""

from __future__ import annotations

from collections.abc import Callable, Iterator

import pytest

from ros_gz_bridge_py.transport.api import MessageInfo
from ros_gz_bridge_py.transport.handles import Subscription
from ros_gz_bridge_py.transport.memory.node import MemoryGzNode
from ros_gz_bridge_py.transport.names import fully_qualified_name
from ros_gz_bridge_py.transport.zmq.routes import DataRouter
from ros_gz_bridge_py.transport.zmq.wire import Frame, encode_data

TYPE = "gz.msgs.StringMsg"


@pytest.fixture
def node() -> Iterator[MemoryGzNode]:
    node = MemoryGzNode("routes_test")
    yield node
    node.close()


def test_every_subscription_of_a_frame_gets_it_read_only(node: MemoryGzNode) -> None:
    fqn = fully_qualified_name("routes_test", "", "/camera")
    got: list[tuple[str, Frame]] = []

    def collector(name: str) -> Callable[[Frame, MessageInfo], None]:
        return lambda payload, _info: got.append((name, payload))

    subs = tuple(
        Subscription(node, "/camera", fqn, TYPE, collector(name), ignore_local=False)
        for name in ("first", "second")
    )
    router = DataRouter(lambda wanted: subs if wanted == fqn else (), "routes_test")
    for _ in range(2):  # decoded and routed, then through the cached route
        frames = encode_data(fqn, "tcp://127.0.0.1:5555", b"", TYPE)
        frames[2] = memoryview(bytearray(b"payload"))  # as the socket reader hands a frame
        router.on_data(frames)
    assert [name for name, _ in got] == ["first", "second"] * 2
    for _, payload in got:
        assert isinstance(payload, memoryview)
        assert payload.readonly
        assert bytes(payload) == b"payload"
    assert router.received == 2


def test_a_bytes_payload_is_handed_as_it_is(node: MemoryGzNode) -> None:
    fqn = fully_qualified_name("routes_test", "", "/chatter")
    got: list[tuple[Frame, MessageInfo]] = []
    sub = Subscription(
        node, "/chatter", fqn, TYPE, lambda p, i: got.append((p, i)), ignore_local=False
    )
    router = DataRouter(lambda wanted: (sub,) if wanted == fqn else (), "routes_test")
    payload = b"hello"
    router.on_data(encode_data(fqn, "tcp://127.0.0.1:5555", payload, TYPE))
    assert got[0][0] is payload
    assert (got[0][1].topic, got[0][1].msg_type) == ("/chatter", TYPE)

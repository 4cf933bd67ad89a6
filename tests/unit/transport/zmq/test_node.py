"""Python <-> Python over real sockets on loopback (env from tests/conftest.py)."""

from __future__ import annotations

import os
import threading
import time
import uuid
from collections.abc import Callable, Iterator
from typing import Any

import pytest
import zmq

from ros_gz_bridge_py.errors import TransportError, TransportTimeoutError
from ros_gz_bridge_py.msgs import GENERIC_TYPE, message_class
from ros_gz_bridge_py.transport import MessageInfo, create_gz_node
from ros_gz_bridge_py.transport.zmq.bulk_context import io_threads
from ros_gz_bridge_py.transport.zmq.node import ZmqGzNode
from testing.polling import wait_until

StringMsg = message_class("gz.msgs.StringMsg")


def publish_until(publish: Callable[[], None], condition: Callable[[], bool]) -> bool:
    """Publish until ``condition``: a NEW_CONNECTION can overtake the SUB's TCP handshake
    (the ZMQ slow joiner, docs/protocol-zmq-data.md §2.8.1), so the first message may be lost, as
    with gz."""
    deadline = time.monotonic() + 10.0
    while not condition():
        if time.monotonic() > deadline:
            return False
        publish()
        time.sleep(0.02)
    return True


def unique(name: str) -> str:
    return f"/{name}_{uuid.uuid4().hex[:8]}"


@pytest.fixture
def nodes() -> Iterator[tuple[ZmqGzNode, ZmqGzNode]]:
    a, b = create_gz_node(), create_gz_node()
    assert isinstance(a, ZmqGzNode)
    assert isinstance(b, ZmqGzNode)
    yield a, b
    a.close()
    b.close()


@pytest.mark.parametrize("msg_type", ["gz.msgs.StringMsg", "ignition.msgs.StringMsg"])
def test_pub_sub_both_type_families(nodes: tuple[ZmqGzNode, ZmqGzNode], msg_type: str) -> None:
    a, b = nodes
    topic = unique("chatter")
    typed: list[tuple[str, MessageInfo]] = []
    raw: list[bytes] = []
    b.subscribe_typed(topic, StringMsg, lambda m, i: typed.append((m.data, i)), msg_type=msg_type)
    b.subscribe(topic, lambda data, _: raw.append(data))
    pub = a.advertise(topic, msg_type)
    assert wait_until(pub.has_connections)
    assert publish_until(lambda: pub.publish(StringMsg(data="hello")), lambda: bool(typed and raw))
    pub.publish_raw(bytearray(StringMsg(data="raw").SerializeToString()))
    assert wait_until(lambda: typed[-1][0] == "raw")
    assert {t[0] for t in typed} == {"hello", "raw"}
    info = typed[0][1]
    assert (info.topic, info.msg_type, info.intra_process) == (topic, msg_type, False)
    assert info.publisher_address == a.pub_address
    assert raw[0] == StringMsg(data="hello").SerializeToString()


def test_type_mismatch_is_not_delivered(nodes: tuple[ZmqGzNode, ZmqGzNode]) -> None:
    a, b = nodes
    topic = unique("typed")
    wrong: list[bytes] = []
    right: list[bytes] = []
    b.subscribe(topic, lambda d, _: wrong.append(d), "gz.msgs.Int32")
    b.subscribe(topic, lambda d, _: right.append(d), "ignition.msgs.StringMsg")
    pub = a.advertise(topic, "ignition.msgs.StringMsg")
    assert wait_until(pub.has_connections)
    assert publish_until(lambda: pub.publish(StringMsg(data="x")), lambda: bool(right))
    assert wrong == []


@pytest.mark.parametrize(
    ("published", "subscribed"),
    [
        ("gz.msgs.StringMsg", "ignition.msgs.StringMsg"),
        ("ignition.msgs.StringMsg", "gz.msgs.StringMsg"),
    ],
)
def test_either_spelling_reaches_subscribers_of_both_once(
    nodes: tuple[ZmqGzNode, ZmqGzNode], published: str, subscribed: str
) -> None:
    """Subscribers of either spelling and a generic one each get every message once."""
    a, b = nodes
    topic = unique("spelled")
    same: list[tuple[bytes, str]] = []
    other: list[tuple[bytes, str]] = []
    generic: list[tuple[bytes, str]] = []
    b.subscribe(topic, lambda d, i: same.append((d, i.msg_type)), published)
    b.subscribe(topic, lambda d, i: other.append((d, i.msg_type)), subscribed)
    b.subscribe(topic, lambda d, i: generic.append((d, i.msg_type)))
    pub = a.advertise(topic, published)
    assert wait_until(pub.has_connections)
    payload = StringMsg(data="once").SerializeToString()
    assert publish_until(lambda: pub.publish_raw(payload), lambda: bool(same and other))
    first = len(same)
    for _ in range(5):
        pub.publish_raw(payload)
    assert wait_until(lambda: len(same) == first + 5 and len(other) == len(same))
    time.sleep(0.2)
    assert len(same) == len(other) == len(generic) == first + 5
    assert {(d, t) for d, t in same} == {(payload, published)}
    assert {(d, t) for d, t in other} == {(payload, published)}


def test_subscriptions_added_and_closed_while_messages_flow(
    nodes: tuple[ZmqGzNode, ZmqGzNode],
) -> None:
    """Received messages take a cached route; a subscription that starts or ends while the
    topic is flowing must be seen at once (the cache is emptied each time)."""
    a, b = nodes
    topic = unique("routes")
    first: list[bytes] = []
    second: list[bytes] = []
    sub_first = b.subscribe(topic, lambda d, _: first.append(d))
    pub = a.advertise(topic, "gz.msgs.StringMsg")
    assert wait_until(pub.has_connections)
    assert publish_until(lambda: pub.publish(StringMsg(data="1")), lambda: bool(first))
    b.subscribe(topic, lambda d, _: second.append(d))
    assert publish_until(lambda: pub.publish(StringMsg(data="2")), lambda: bool(second))
    sub_first.close()
    count = len(first)
    before = len(second)
    assert publish_until(lambda: pub.publish(StringMsg(data="3")), lambda: len(second) > before)
    assert len(first) == count
    assert StringMsg.FromString(second[-1]).data == "3"


def test_no_wire_traffic_without_subscribers_and_listing(
    nodes: tuple[ZmqGzNode, ZmqGzNode],
) -> None:
    a, b = nodes
    topic = unique("listed")
    pub = a.advertise(topic, "gz.msgs.StringMsg")
    assert not pub.has_connections()
    found = b.wait_for_publishers(topic, 10.0)
    # Announced under both spellings, from one address.
    assert sorted((i.topic, i.msg_type, i.process_uuid, i.address) for i in found) == [
        (topic, "gz.msgs.StringMsg", a.process_uuid, a.pub_address),
        (topic, "ignition.msgs.StringMsg", a.process_uuid, a.pub_address),
    ]
    assert topic in b.topic_list()
    assert b.topic_info(topic) == found
    assert b.wait_for_publishers(topic, 0.1, msg_type="gz.msgs.Other") == []
    sub = b.subscribe(topic, lambda *_: None)
    assert wait_until(pub.has_connections)
    sub.close()
    assert wait_until(lambda: not pub.has_connections())
    pub.close()
    assert wait_until(lambda: b.topic_info(topic) == [])


def test_local_delivery_and_ignore_local() -> None:
    with create_gz_node() as node:
        topic = unique("local")
        seen: list[MessageInfo] = []
        ignored: list[bytes] = []
        node.subscribe(topic, lambda _, info: seen.append(info))
        node.subscribe(topic, lambda d, _: ignored.append(d), ignore_local=True)
        pub = node.advertise(topic, "gz.msgs.StringMsg")
        assert pub.has_connections()
        pub.publish(StringMsg(data="me"))
        assert wait_until(lambda: len(seen) == 1)
        assert seen[0].intra_process
        assert seen[0].publisher_address == ""
        assert ignored == []


def test_queue_size_drops_oldest() -> None:
    with create_gz_node() as node:
        topic = unique("queue")
        release = threading.Event()
        entered = threading.Event()
        got: list[str] = []

        def slow(msg: Any, _: MessageInfo) -> None:
            entered.set()
            release.wait(10)
            got.append(msg.data)

        sub = node.subscribe_typed(topic, StringMsg, slow, queue_size=2)
        pub = node.advertise(topic, "gz.msgs.StringMsg")
        pub.publish(StringMsg(data="0"))
        assert entered.wait(5)
        for i in range(1, 6):
            pub.publish(StringMsg(data=str(i)))
        release.set()
        assert wait_until(lambda: len(got) == 3)
        assert got == ["0", "4", "5"]
        assert sub.dropped == 3
        assert node.stats.messages_dropped == 3


def test_queued_subscriptions_read_only_their_own_topic(nodes: tuple[ZmqGzNode, ZmqGzNode]) -> None:
    """A queued subscription reads its own SUB socket, subscribed by topic prefix as ZeroMQ
    does: messages of a longer topic sharing the prefix must not reach it, nor a type it does
    not accept; a queued and an unqueued subscription of one topic each get every message."""
    a, b = nodes
    short = unique("prefix")
    longer = short + "_longer"
    got: dict[str, list[str]] = {"short": [], "longer": [], "unqueued": [], "wrong_type": []}

    def into(key: str) -> Callable[[Any, MessageInfo], None]:
        return lambda msg, _info: got[key].append(msg.data)

    b.subscribe_typed(short, StringMsg, into("short"), queue_size=10)
    b.subscribe_typed(short, StringMsg, into("unqueued"))
    b.subscribe_typed(longer, StringMsg, into("longer"), queue_size=10)
    b.subscribe_typed(
        longer, StringMsg, into("wrong_type"), msg_type="gz.msgs.Int32", queue_size=10
    )
    pub_short = a.advertise(short, "gz.msgs.StringMsg")
    pub_longer = a.advertise(longer, "gz.msgs.StringMsg")
    assert wait_until(lambda: pub_short.has_connections() and pub_longer.has_connections())
    received_before = b.stats.messages_received
    assert publish_until(
        lambda: pub_longer.publish(StringMsg(data="long")), lambda: bool(got["longer"])
    )
    assert publish_until(
        lambda: pub_short.publish(StringMsg(data="short")),
        lambda: bool(got["short"]) and bool(got["unqueued"]),
    )
    time.sleep(0.2)  # anything misrouted would have arrived by now
    assert set(got["short"]) == set(got["unqueued"]) == {"short"}
    assert set(got["longer"]) == {"long"}
    assert got["wrong_type"] == []
    # Counted once per socket that read it for a subscription of its topic: the readers'
    # messages are in the stats, and the shared socket does not count "long" messages that
    # reached it only because their topic starts with the unqueued subscription's.
    delivered = len(got["short"]) + len(got["unqueued"]) + len(got["longer"])
    assert b.stats.messages_received == received_before + delivered


def test_on_delivery_start_runs_on_the_subscription_thread() -> None:
    with create_gz_node() as node:
        topic = unique("start")
        threads: list[tuple[str, int]] = []
        node.subscribe(
            topic,
            lambda _p, _i: threads.append(("message", threading.get_ident())),
            queue_size=4,
            on_delivery_start=lambda: threads.append(("start", threading.get_ident())),
        )
        node.advertise(topic, "gz.msgs.StringMsg").publish(StringMsg(data="x"))
        assert wait_until(lambda: len(threads) == 2)
        assert [what for what, _ in threads] == ["start", "message"]
        assert threads[0][1] == threads[1][1] != threading.get_ident()


def test_a_queue_of_no_messages_is_refused() -> None:
    with create_gz_node() as node, pytest.raises(ValueError, match="queue_size must be at least 1"):
        node.subscribe(unique("noroom"), lambda _p, _i: None, queue_size=0)


def test_on_delivery_start_without_a_queue_is_refused() -> None:
    with create_gz_node() as node, pytest.raises(ValueError, match="needs a queue_size"):
        node.subscribe(unique("noqueue"), lambda _p, _i: None, on_delivery_start=lambda: None)


def test_callback_errors_are_counted(nodes: tuple[ZmqGzNode, ZmqGzNode]) -> None:
    a, b = nodes
    topic = unique("boom")
    calls: list[int] = []

    def boom(_: bytes, __: MessageInfo) -> None:
        calls.append(1)
        msg = "callback failure"
        raise RuntimeError(msg)

    b.subscribe(topic, boom)
    pub = a.advertise(topic, "gz.msgs.StringMsg")
    assert wait_until(pub.has_connections)
    assert publish_until(lambda: pub.publish_raw(b"\x12\x01a"), lambda: len(calls) >= 2)
    assert wait_until(lambda: b.stats.callback_errors == len(calls))
    bad: list[Any] = []
    b.subscribe_typed(topic, StringMsg, lambda m, _: bad.append(m))
    assert publish_until(
        lambda: pub.publish_raw(b"\xff\xff\xff"), lambda: b.stats.payloads_undecodable >= 1
    )
    assert bad == []


def test_services(nodes: tuple[ZmqGzNode, ZmqGzNode]) -> None:
    a, b = nodes
    echo, fail, oneway = unique("echo"), unique("fail"), unique("oneway")
    t = "gz.msgs.StringMsg"
    received: list[bytes] = []
    a.advertise_service(echo, t, t, lambda req: (True, req + b"!"))
    a.advertise_service(fail, t, t, lambda req: (False, b"ignored"))

    def one_way(request: bytes) -> tuple[bool, bytes]:
        received.append(request)
        return True, b""

    a.advertise_service(oneway, t, "gz.msgs.Empty", one_way)
    assert b.request(echo, b"\x12\x01x", t, t, 10.0) == (True, b"\x12\x01x!")
    assert b.request(fail, b"", t, t, 10.0) == (False, b"")
    assert b.request(oneway, b"1", t, "gz.msgs.Empty", 10.0) == (True, b"")
    assert wait_until(lambda: received == [b"1"])
    assert echo in b.service_list()
    (info,) = b.service_info(echo)
    assert (info.msg_type, info.request_type, info.response_type) == (f"{t}&{t}", t, t)
    # Either spelling of a type reaches the provider; another type gets no reply.
    assert b.request(echo, b"\x12\x01y", "ignition.msgs.StringMsg", t, 10.0) == (
        True,
        b"\x12\x01y!",
    )
    with pytest.raises(TransportTimeoutError):
        b.request(echo, b"", "gz.msgs.Int32", t, 0.5)
    # Async with a callback, and a local service of the same node.
    replies: list[tuple[bool | None, bytes]] = []
    a.request_async(echo, b"L", t, t, 5.0, lambda ok, data: replies.append((ok, data)))
    assert wait_until(lambda: replies == [(True, b"L!")])


def test_request_timeout_and_unknown_service() -> None:
    with create_gz_node() as node:
        replies: list[tuple[bool | None, bytes]] = []
        node.request_async(
            unique("nobody"), b"", "a", "b", 0.2, lambda ok, d: replies.append((ok, d))
        )
        assert wait_until(lambda: replies == [(None, b"")])


def test_request_from_io_thread_is_refused() -> None:
    with create_gz_node() as node:
        topic = unique("io")
        errors: list[Exception] = []

        def call(_: bytes, __: MessageInfo) -> None:
            try:
                node.request("/x", b"", "a", "b", 0.1)
            except TransportError as error:
                errors.append(error)

        pub = node.advertise(topic, "gz.msgs.StringMsg")
        node.subscribe(topic, call)
        # Intra-process delivery runs in this thread; make the I/O thread run the callback.
        other = create_gz_node()
        try:
            remote = other.advertise(topic, "gz.msgs.StringMsg")
            assert wait_until(remote.has_connections)
            assert publish_until(lambda: remote.publish_raw(b""), lambda: bool(errors))
        finally:
            other.close()
        assert pub.topic == topic


def test_close_leaves_no_threads_and_is_idempotent() -> None:
    before = set(threading.enumerate())
    node = create_gz_node()
    node.subscribe(unique("q"), lambda *_: None, queue_size=3)
    node.advertise(unique("p"), "gz.msgs.StringMsg")
    node.close()
    node.close()
    assert set(threading.enumerate()) <= before
    with pytest.raises(TransportError):
        node.advertise("/late", GENERIC_TYPE)


def test_a_publisher_of_large_messages_has_a_send_queue_sized_in_bytes(
    nodes: tuple[ZmqGzNode, ZmqGzNode],
) -> None:
    """``queue_bytes``: the publisher sends from a socket of its own, at its own address, whose
    SNDHWM (set before the bind, docs/protocol-zmq-data.md §2.8.8) holds ``queue_bytes`` of the
    largest messages the transport carries; messages reach a subscriber as from any publisher."""
    from ros_gz_bridge_py.transport.zmq.hwm import hwm_for_bytes  # noqa: PLC0415

    a, b = nodes
    topic = unique("large")
    got: list[str] = []
    b.subscribe_typed(topic, StringMsg, lambda m, _: got.append(m.data))
    budget = 8 * a.settings.max_message_size
    pub = a.advertise(topic, "gz.msgs.StringMsg", queue_bytes=budget)
    sock = pub.sock  # type: ignore[attr-defined]
    assert sock is not None
    assert (
        pub.send_queue()
        == sock.getsockopt(zmq.SNDHWM)
        == hwm_for_bytes(a.settings.max_message_size, budget, a.settings.sndhwm)
        == 8
    )
    assert pub.records[0].address != a.pub_address  # type: ignore[attr-defined]
    assert wait_until(pub.has_connections)
    assert publish_until(lambda: pub.publish(StringMsg(data="image")), lambda: bool(got))
    assert set(got) == {"image"}
    small = a.advertise(unique("small"), "gz.msgs.StringMsg")
    assert small.sock is None  # type: ignore[attr-defined]
    assert small.send_queue() == a.settings.sndhwm


#: How much a large topic's delivery thread lowers its priority (bulk_context.py).
LOWER_BY = 3


def _nice(tid: int) -> int:
    return os.getpriority(os.PRIO_PROCESS, tid)


def test_a_large_topic_is_read_by_an_io_thread_of_its_own_at_its_delivery_priority(
    nodes: tuple[ZmqGzNode, ZmqGzNode],
) -> None:
    a, b = nodes
    before = set(io_threads())
    topic = unique("bulk")
    delivered: list[int] = []

    def lower_own_priority() -> None:
        tid = threading.get_native_id()
        os.setpriority(os.PRIO_PROCESS, tid, _nice(tid) + LOWER_BY)

    a.subscribe(
        topic,
        lambda _p, _i: delivered.append(threading.get_native_id()),
        "gz.msgs.StringMsg",
        queue_size=4,
        on_delivery_start=lower_own_priority,
        large_messages=True,
    )
    publisher = b.advertise(topic, "gz.msgs.StringMsg")
    assert publish_until(lambda: publisher.publish(StringMsg(data="x")), lambda: bool(delivered))
    ours = set(io_threads()) - before
    assert len(ours) == 1  # made with the node's first large-message subscription
    delivery_nice = _nice(delivered[0])
    assert delivery_nice == _nice(threading.get_native_id()) + LOWER_BY
    assert [_nice(tid) for tid in ours] == [delivery_nice]
    a.close()
    assert wait_until(lambda: not ours & set(io_threads()))


def test_small_topics_make_no_io_thread_of_their_own(nodes: tuple[ZmqGzNode, ZmqGzNode]) -> None:
    a, b = nodes
    before = set(io_threads())
    topic = unique("small")
    delivered: list[bytes] = []
    a.subscribe(topic, lambda p, _i: delivered.append(bytes(p)), "gz.msgs.StringMsg", queue_size=4)
    publisher = b.advertise(topic, "gz.msgs.StringMsg")
    assert publish_until(lambda: publisher.publish(StringMsg(data="x")), lambda: bool(delivered))
    assert set(io_threads()) == before

"""What every Gazebo Transport backend must do: one suite, run against each of them.

Two nodes of one backend play two processes: ZeroMQ over loopback (the environment of
tests/conftest.py), Zenoh in peer mode on an explicit ``tcp/127.0.0.1`` port with scouting
off, and the in-memory backend on a network of their own. A new backend is written by adding
it to ``BACKENDS`` in ``ros_gz_bridge_py.transport`` and to :func:`pair`, and passing this.
Interoperability with real Gazebo is tested elsewhere (tests/interop, against ign-transport 11).
"""

from __future__ import annotations

import dataclasses
import threading
import time
import uuid
from collections.abc import Callable, Iterator

import pytest

from ros_gz_bridge_py.errors import TransportError, TransportTimeoutError
from ros_gz_bridge_py.msgs import message_class
from ros_gz_bridge_py.msgs.names import same_message
from ros_gz_bridge_py.transport import BACKENDS, GzNode, MessageInfo, Rejection, TransportSettings
from ros_gz_bridge_py.transport.api import PUBLISHER, SUBSCRIBER
from ros_gz_bridge_py.transport.memory.network import MemoryNetwork
from ros_gz_bridge_py.transport.memory.node import MemoryGzNode
from ros_gz_bridge_py.transport.zenoh.config import endpoints_config
from ros_gz_bridge_py.transport.zenoh.node import ZenohGzNode
from ros_gz_bridge_py.transport.zmq.node import ZmqGzNode
from testing.loopback import free_port
from testing.polling import wait_until

GZ, IGN = "gz.msgs.StringMsg", "ignition.msgs.StringMsg"
StringMsg = message_class(GZ)
LIMIT = 10.0


def publish_until(publish: Callable[[], None], condition: Callable[[], bool]) -> bool:
    """Publish until ``condition``: the first messages after a match may be lost (the ZeroMQ
    slow joiner, docs/protocol-zmq-data.md §2.8.1), as with gz."""
    deadline = time.monotonic() + LIMIT
    while not condition():
        if time.monotonic() > deadline:
            return False
        publish()
        time.sleep(0.02)
    return True


def unique(name: str) -> str:
    return f"/{name}_{uuid.uuid4().hex[:8]}"


def _zenoh_pair(settings: TransportSettings | None = None) -> tuple[GzNode, GzNode]:
    where = f"tcp/127.0.0.1:{free_port()}"
    a = ZenohGzNode(settings=settings, config=endpoints_config("peer", listen=[where]))
    b = ZenohGzNode(settings=settings, config=endpoints_config("peer", connect=[where]))
    return a, b


def _memory_pair(settings: TransportSettings | None = None) -> tuple[GzNode, GzNode]:
    network = MemoryNetwork()
    return (
        MemoryGzNode(settings=settings, network=network),
        MemoryGzNode(settings=settings, network=network),
    )


#: Two nodes of each backend that see each other, with the given settings (None: from the
#: environment).
MAKERS: dict[str, Callable[[TransportSettings | None], tuple[GzNode, GzNode]]] = {
    "zeromq": lambda settings: (ZmqGzNode(settings=settings), ZmqGzNode(settings=settings)),
    "zenoh": _zenoh_pair,
    "memory": _memory_pair,
}


def test_every_registered_backend_is_under_contract() -> None:
    assert set(MAKERS) == set(BACKENDS)


@pytest.fixture(params=sorted(MAKERS))
def pair(request: pytest.FixtureRequest) -> Iterator[tuple[GzNode, GzNode]]:
    """Two nodes of one backend that see each other."""
    a, b = MAKERS[request.param](None)
    yield a, b
    a.close()
    b.close()


#: The maximum message size of :func:`limited_pair`.
SMALL_LIMIT = 100_000


@pytest.fixture(params=sorted(MAKERS))
def limited_pair(request: pytest.FixtureRequest) -> Iterator[tuple[str, GzNode, GzNode]]:
    """Two nodes of one backend whose maximum message size is :data:`SMALL_LIMIT`."""
    settings = dataclasses.replace(TransportSettings.from_env(), max_message_size=SMALL_LIMIT)
    a, b = MAKERS[request.param](settings)
    yield request.param, a, b
    a.close()
    b.close()


class Inbox:
    """What one subscription callback received, in order."""

    def __init__(self) -> None:
        self.items: list[tuple[bytes, MessageInfo]] = []
        self.threads: set[int] = set()

    def __call__(self, payload: bytes, info: MessageInfo) -> None:
        self.items.append((bytes(payload), info))
        self.threads.add(threading.get_ident())

    def texts(self) -> list[str]:
        return [StringMsg.FromString(payload).data for payload, _ in self.items]


def test_remote_messages_reach_typed_and_raw_subscriptions(pair: tuple[GzNode, GzNode]) -> None:
    a, b = pair
    topic = unique("chatter")
    typed: list[tuple[str, MessageInfo]] = []
    raw = Inbox()
    b.subscribe_typed(topic, StringMsg, lambda m, i: typed.append((m.data, i)))
    b.subscribe(topic, raw, GZ)
    pub = a.advertise(topic, GZ)
    assert wait_until(pub.has_connections)
    assert publish_until(
        lambda: pub.publish(StringMsg(data="hi")), lambda: bool(typed and raw.items)
    )
    info = typed[0][1]
    assert (typed[0][0], info.topic, info.msg_type, info.intra_process) == ("hi", topic, GZ, False)
    assert info.partition == b.partition
    assert raw.texts()[0] == "hi"


@pytest.mark.parametrize(("published", "subscribed"), [(GZ, IGN), (IGN, GZ)])
def test_either_spelling_reaches_every_subscriber_once(
    pair: tuple[GzNode, GzNode], published: str, subscribed: str
) -> None:
    """docs/protocol-lines.md §9: a subscriber of either spelling and a generic one each get every
    message exactly once."""
    a, b = pair
    topic = unique("spelled")
    same, other, generic = Inbox(), Inbox(), Inbox()
    b.subscribe(topic, same, published)
    b.subscribe(topic, other, subscribed)
    b.subscribe(topic, generic)
    pub = a.advertise(topic, published)
    payload = StringMsg(data="once").SerializeToString()
    assert publish_until(
        lambda: pub.publish_raw(payload), lambda: bool(same.items and other.items and generic.items)
    )
    first = [len(same.items), len(other.items), len(generic.items)]
    for _ in range(5):
        pub.publish_raw(payload)
    assert wait_until(
        lambda: [len(same.items), len(other.items), len(generic.items)] == [n + 5 for n in first]
    )
    time.sleep(0.2)
    assert [len(same.items), len(other.items), len(generic.items)] == [n + 5 for n in first]
    assert pub.wire_types()
    assert all(same_message(t, published) for t in pub.wire_types())


def test_another_type_is_not_delivered(pair: tuple[GzNode, GzNode]) -> None:
    a, b = pair
    topic = unique("typed")
    wrong, right = Inbox(), Inbox()
    b.subscribe(topic, wrong, "gz.msgs.Int32")
    b.subscribe(topic, right, GZ)
    pub = a.advertise(topic, GZ)
    assert publish_until(lambda: pub.publish(StringMsg(data="x")), lambda: bool(right.items))
    assert wrong.items == []


def test_another_type_is_told_to_on_reject(pair: tuple[GzNode, GzNode]) -> None:
    """issue 14: a message of the topic that a subscription does not take is counted and told,
    never dropped without a word."""
    a, b = pair
    topic = unique("wrong")
    told: list[tuple[Rejection, str]] = []
    right = Inbox()
    b.subscribe(topic, Inbox(), "gz.msgs.Int32", queue_size=10, on_reject=lambda *r: told.append(r))
    b.subscribe(topic, right, GZ)
    pub = a.advertise(topic, GZ)
    assert publish_until(lambda: pub.publish(StringMsg(data="x")), lambda: bool(told))
    assert told[0][0] is Rejection.WRONG_TYPE
    assert GZ in told[0][1]
    assert b.stats.messages_wrong_type >= 1


def test_messages_over_the_size_limit_are_refused(
    limited_pair: tuple[str, GzNode, GzNode],
) -> None:
    """issue 14: a message over ``max_message_size`` never reaches the callback, later ones
    do. ZeroMQ and memory count it and tell ``on_reject``; Zenoh is given the limit and drops
    such a message inside Zenoh, which reports nothing (docs/protocol-zenoh.md §4.2)."""
    backend, a, b = limited_pair
    topic = unique("big")
    inbox = Inbox()
    told: list[tuple[Rejection, str]] = []
    b.subscribe(topic, inbox, GZ, queue_size=10, on_reject=lambda *r: told.append(r))
    pub = a.advertise(topic, GZ)
    assert wait_until(pub.has_connections)
    small = StringMsg(data="small").SerializeToString()
    assert publish_until(lambda: pub.publish_raw(small), lambda: bool(inbox.items))
    pub.publish(StringMsg(data="x" * (2 * SMALL_LIMIT)))
    if backend != "zenoh":
        assert wait_until(lambda: [r for r, _ in told] == [Rejection.OVERSIZE])
        assert b.stats.messages_oversize == 1
    before = len(inbox.items)
    assert publish_until(lambda: pub.publish_raw(small), lambda: len(inbox.items) > before)
    assert set(inbox.texts()) == {"small"}


def test_local_delivery_and_ignore_local(pair: tuple[GzNode, GzNode]) -> None:
    a, _ = pair
    topic = unique("local")
    seen, ignoring = Inbox(), Inbox()
    a.subscribe(topic, seen, IGN)
    a.subscribe(topic, ignoring, GZ, ignore_local=True)
    pub = a.advertise(topic, GZ)
    assert pub.has_connections()  # a local subscription counts
    assert pub.wire_types() == frozenset()  # nobody remote
    pub.publish(StringMsg(data="me"))
    assert wait_until(lambda: bool(seen.items))
    assert seen.items[0][1].intra_process
    assert seen.items[0][1].msg_type == GZ
    time.sleep(0.1)
    assert ignoring.items == []


def test_connections_follow_remote_subscriptions(pair: tuple[GzNode, GzNode]) -> None:
    a, b = pair
    topic = unique("conn")
    pub = a.advertise(topic, GZ)
    assert not pub.has_connections()
    sub = b.subscribe(topic, Inbox(), IGN)
    assert wait_until(pub.has_connections)
    assert pub.wire_types() == {IGN} or pub.wire_types() == {GZ}  # Zenoh peers say gz.msgs
    other = b.subscribe(topic, Inbox(), GZ)
    sub.close()
    assert pub.has_connections()
    other.close()
    assert wait_until(lambda: not pub.has_connections())
    pub.close()
    pub.close()  # idempotent


def test_queue_drops_the_oldest_on_its_own_thread(pair: tuple[GzNode, GzNode]) -> None:
    a, _ = pair
    topic = unique("queued")
    release, handling = threading.Event(), threading.Event()
    started: list[int] = []
    got: list[str] = []

    def slow(payload: bytes, _info: MessageInfo) -> None:
        handling.set()
        release.wait(LIMIT)
        got.append(StringMsg.FromString(payload).data)

    sub = a.subscribe(
        topic,
        slow,
        GZ,
        queue_size=2,
        on_delivery_start=lambda: started.append(threading.get_ident()),
    )
    pub = a.advertise(topic, GZ)
    pub.publish(StringMsg(data="0"))
    assert handling.wait(LIMIT)  # the delivery thread holds "0"
    for index in range(1, 6):
        pub.publish(StringMsg(data=str(index)))
    assert wait_until(lambda: sub.dropped == 3)
    release.set()
    assert wait_until(lambda: got == ["0", "4", "5"])
    assert a.stats.messages_dropped == 3
    assert started
    assert started[0] != threading.get_ident()
    with pytest.raises(ValueError, match="at least 1"):
        a.subscribe(topic, slow, GZ, queue_size=0)
    with pytest.raises(ValueError, match="needs a queue_size"):
        a.subscribe(topic, slow, GZ, on_delivery_start=lambda: None)


def test_a_queue_is_bounded_in_bytes_as_well_as_messages(
    pair: tuple[GzNode, GzNode], caplog: pytest.LogCaptureFixture
) -> None:
    """A queue of 1000 messages and 3 MB behind a callback that holds the first message: 40
    messages of 1 MB from the other node leave the newest 3 in the queue; the others are
    dropped, counted and told in one warning that names the topic (before: the byte bound was
    the fixed 64 MiB, so the queue took every one of them)."""
    a, b = pair
    topic = unique("bytes")
    release, handling = threading.Event(), threading.Event()
    got: list[str] = []
    payload = 1_000_000

    def slow(data: bytes, _info: MessageInfo) -> None:
        handling.set()
        release.wait(LIMIT)
        got.append(StringMsg.FromString(data).data[:3])

    sub = a.subscribe(topic, slow, GZ, queue_size=1000, queue_bytes=3 * (payload + 10))
    pub = b.advertise(topic, GZ)
    assert publish_until(lambda: pub.publish(StringMsg(data="hld")), handling.is_set)
    sent = 40
    for index in range(sent):
        pub.publish(StringMsg(data=f"{index:03d}".ljust(payload, "x")))
        time.sleep(0.005)
    assert wait_until(lambda: sub.dropped >= sent - 3)
    release.set()
    assert wait_until(lambda: got[-3:] == ["037", "038", "039"])
    # a second "hld" may have crossed the first: then it was dropped too
    assert sent - 3 <= sub.dropped == a.stats.messages_dropped <= sent - 2
    assert f"{topic}: " in caplog.text or f"{a.fqn(topic)}: " in caplog.text
    assert "parameter max_queued_bytes" in caplog.text


def test_callback_errors_are_counted_not_raised(pair: tuple[GzNode, GzNode]) -> None:
    a, b = pair
    topic = unique("raising")
    calls: list[int] = []

    def boom(_payload: bytes, _info: MessageInfo) -> None:
        calls.append(1)
        msg = "boom"
        raise RuntimeError(msg)

    b.subscribe(topic, boom, GZ)
    pub = a.advertise(topic, GZ)
    assert publish_until(lambda: pub.publish(StringMsg(data="x")), lambda: bool(calls))
    assert wait_until(lambda: b.stats.callback_errors >= 1)


def test_listings_and_waiting_for_publishers(pair: tuple[GzNode, GzNode]) -> None:
    a, b = pair
    topic = unique("listed")
    pub = a.advertise(topic, GZ)
    found = b.wait_for_publishers(topic, LIMIT)
    assert found
    assert {i.process_uuid for i in found} == {a.process_uuid}
    assert any(i.msg_type == GZ for i in found)
    assert topic in b.topic_list()
    assert b.wait_for_publishers(topic, 0.1, msg_type="gz.msgs.Other") == []
    pub.close()
    assert wait_until(lambda: b.topic_info(topic) == [])


def test_services_in_either_spelling(pair: tuple[GzNode, GzNode]) -> None:
    a, b = pair
    echo, fail, one_way = unique("echo"), unique("fail"), unique("oneway")
    received: list[bytes] = []
    a.advertise_service(echo, GZ, GZ, lambda req: (True, req + b"!"))
    a.advertise_service(fail, GZ, GZ, lambda req: (False, b"ignored"))

    def note(request: bytes) -> tuple[bool, bytes]:
        received.append(request)
        return True, b""

    a.advertise_service(one_way, GZ, "gz.msgs.Empty", note)
    assert b.request(echo, b"\x12\x01x", GZ, GZ, LIMIT) == (True, b"\x12\x01x!")
    assert b.request(echo, b"\x12\x01y", IGN, IGN, LIMIT) == (True, b"\x12\x01y!")
    assert b.request(fail, b"\x12\x01z", GZ, GZ, LIMIT) == (False, b"")
    assert b.request(one_way, b"1", GZ, "ignition.msgs.Empty", LIMIT) == (True, b"")
    assert wait_until(lambda: received == [b"1"])
    with pytest.raises(TransportTimeoutError):
        b.request(echo, b"", "gz.msgs.Int32", GZ, 0.3)
    with pytest.raises(TransportTimeoutError):
        b.request(unique("nobody"), b"", GZ, GZ, 0.3)
    # A node's own service answers its own calls.
    assert a.request(echo, b"L", GZ, GZ, LIMIT) == (True, b"L!")
    assert echo in b.service_list()
    (info,) = b.service_info(echo)
    assert (info.request_type, info.response_type) == (GZ, GZ)


def test_async_callbacks_run_once_and_blocking_on_the_node_thread_is_refused(
    pair: tuple[GzNode, GzNode],
) -> None:
    a, b = pair
    service = unique("async")
    a.advertise_service(service, GZ, GZ, lambda req: (True, req))
    replies: list[tuple[bool | None, bytes]] = []
    refused: list[BaseException] = []

    def on_reply(ok: bool | None, payload: bytes) -> None:
        replies.append((ok, payload))
        try:
            b.request(service, b"again", GZ, GZ, 1.0)
        except TransportError as error:
            refused.append(error)

    b.request_async(service, b"q", GZ, GZ, LIMIT, on_reply)
    assert wait_until(lambda: bool(replies))
    time.sleep(0.2)
    assert replies == [(True, b"q")]
    if refused:  # backends whose replies run on the node's own thread must refuse
        assert "would block" in str(refused[0])


def test_observe_sees_other_processes_in_every_partition(pair: tuple[GzNode, GzNode]) -> None:
    a, b = pair
    topic = unique("observed")
    b.subscribe(topic, Inbox(), GZ)
    pub = a.advertise(topic, GZ)
    assert wait_until(pub.has_connections)

    def seen_by_b() -> set[tuple[str, str]]:
        return {(e.role, e.process_uuid) for e in b.observe(topic)}

    assert wait_until(lambda: (PUBLISHER, a.process_uuid) in seen_by_b())
    assert wait_until(
        lambda: (SUBSCRIBER, b.process_uuid) in {(e.role, e.process_uuid) for e in a.observe(topic)}
    )
    published = [e for e in b.observe(topic) if e.role == PUBLISHER]
    assert all(e.partition == a.partition and same_message(e.msg_type, GZ) for e in published)
    assert a.peer_processes() >= 1
    assert a.partition in a.listening()


def test_graph_lists_every_topic_of_other_processes(pair: tuple[GzNode, GzNode]) -> None:
    a, b = pair
    published, subscribed = unique("graph_pub"), unique("graph_sub")
    pub = a.advertise(published, GZ)
    sub = a.subscribe_typed(subscribed, StringMsg, Inbox())

    def seen_by_b() -> set[tuple[str, str, str]]:
        return {(e.role, e.topic, e.process_uuid) for e in b.graph()}

    assert wait_until(
        lambda: (
            {(PUBLISHER, published, a.process_uuid), (SUBSCRIBER, subscribed, a.process_uuid)}
            <= seen_by_b()
        )
    )
    mine = [e for e in b.graph() if e.process_uuid == a.process_uuid]
    assert all(e.partition == a.partition for e in mine)
    assert all(
        same_message(e.msg_type, GZ) for e in mine if e.role == PUBLISHER
    )  # typed subscribers' types: where the protocol tells (Zenoh, memory; ZeroMQ 13+ on asking)
    assert not any(e.process_uuid == b.process_uuid for e in b.graph())
    assert {(e.role, e.process_uuid) for e in b.observe(published)} <= {
        (e.role, e.process_uuid) for e in b.graph() if e.topic == published
    }
    pub.close()
    sub.close()
    assert wait_until(lambda: (PUBLISHER, published, a.process_uuid) not in seen_by_b())


def test_closing_is_idempotent_and_each_handle_closes_only_itself(
    pair: tuple[GzNode, GzNode],
) -> None:
    a, b = pair
    topic = unique("handles")
    first, second = Inbox(), Inbox()
    sub_first = b.subscribe(topic, first, GZ)
    b.subscribe(topic, second, GZ)
    pub = a.advertise(topic, GZ)
    assert publish_until(
        lambda: pub.publish(StringMsg(data="a")), lambda: bool(first.items and second.items)
    )
    sub_first.close()
    sub_first.close()
    before = len(second.items)
    assert publish_until(
        lambda: pub.publish(StringMsg(data="b")), lambda: len(second.items) > before
    )
    count = len(first.items)
    time.sleep(0.1)
    assert len(first.items) == count
    a.close()
    a.close()
    pub.publish(StringMsg(data="after close"))  # nothing happens, nothing raises
    with pytest.raises(TransportError):
        a.advertise(unique("late"), GZ)

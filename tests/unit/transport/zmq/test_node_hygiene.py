"""The ZeroMQ node against hostile and vanished peers (issue 14, points 2-4), in-process.

Rogue publishers and fake peers are raw pyzmq sockets and raw discovery datagrams on
loopback (``testing/rogue.py``); each test is bounded in what it sends and in time.
"""

from __future__ import annotations

import dataclasses
import subprocess
import sys
import textwrap
import time
import uuid
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
import zmq

from ros_gz_bridge_py.msgs import message_class
from ros_gz_bridge_py.transport import MessageInfo, Rejection, TransportSettings
from ros_gz_bridge_py.transport.zmq.node import ZmqGzNode
from ros_gz_bridge_py.transport.zmq.wire import ServiceRequest, encode_request
from testing.polling import wait_until
from testing.rogue import FakePeer, RoguePublisher, TrapListeners

STRING = "gz.msgs.StringMsg"
StringMsg = message_class(STRING)
LIMIT = 1_000_000


def unique(name: str) -> str:
    return f"/{name}_{uuid.uuid4().hex[:8]}"


class Sink:
    """What a subscription delivered and what it was told it could not use."""

    def __init__(self) -> None:
        self.texts: list[str] = []
        self.rejections: list[tuple[Rejection, str]] = []

    def __call__(self, payload: bytes, _info: MessageInfo) -> None:
        self.texts.append(StringMsg.FromString(payload).data)

    def reject(self, reason: Rejection, detail: str) -> None:
        self.rejections.append((reason, detail))

    def reasons(self) -> list[Rejection]:
        return [reason for reason, _ in self.rejections]


@pytest.fixture
def node() -> Iterator[ZmqGzNode]:
    settings = dataclasses.replace(TransportSettings.from_env(), max_message_size=LIMIT)
    with ZmqGzNode(settings=settings) as gz_node:
        yield gz_node


@pytest.mark.parametrize("queued", [True, False])
def test_an_oversize_frame_is_refused_counted_and_the_publisher_reconnected(
    node: ZmqGzNode, queued: bool
) -> None:
    """libzmq drops the connection while reading the frame's size (ZMQ_MAXMSGSIZE) and does
    not reconnect; we count the refusal and reconnect, so the same publisher's next message
    arrives."""
    topic = unique("big")
    sink = Sink()
    node.subscribe(topic, sink, STRING, queue_size=10 if queued else None, on_reject=sink.reject)
    rogue = RoguePublisher(node.fqn(topic), STRING)
    try:
        assert rogue.wait_subscribed(10)
        rogue.send(memoryview(bytes(5 * LIMIT)))
        assert wait_until(lambda: node.stats.messages_oversize == 1)
        if queued:
            assert sink.reasons() == [Rejection.OVERSIZE]
            assert "GZ_TRANSPORT_MAX_MESSAGE_SIZE" in sink.rejections[0][1]
        assert rogue.wait_subscribed(10), "we reconnect after the refusal"
        small = StringMsg(data="small").SerializeToString()
        deadline = time.monotonic() + 5
        while not sink.texts and time.monotonic() < deadline:  # the new pipe may lag a moment
            rogue.send(small)
            time.sleep(0.05)
        assert set(sink.texts) == {"small"}
        assert node.stats.messages_oversize == 1
    finally:
        rogue.close()


def test_malformed_frames_and_another_type_are_told_to_the_subscription(node: ZmqGzNode) -> None:
    topic = unique("junk")
    queued, direct = Sink(), Sink()
    node.subscribe(topic, queued, STRING, queue_size=10, on_reject=queued.reject)
    node.subscribe(topic, direct, STRING, on_reject=direct.reject)
    rogue = RoguePublisher(node.fqn(topic), STRING)
    try:
        # Both sockets subscribe: the reader's and the shared one.
        assert wait_until(lambda: rogue.wait_subscribed(0.1) and rogue.subscriptions >= 2)
        time.sleep(0.3)  # a subscription can reach the rogue before the SUB reads the pipe
        fqn = node.fqn(topic).encode()
        rogue.send_frames([fqn, b"tcp://127.0.0.1:1", b"x"])  # three frames
        rogue.send_frames([fqn, b"tcp://127.0.0.1:1", b"x", b"\xff\xfe"])  # type not UTF-8
        rogue.send(StringMsg(data="int").SerializeToString(), "gz.msgs.Int32")
        rogue.send_frames([fqn + b"_other", b"a", b"b"])  # another topic's: not told
        rogue.send(StringMsg(data="ok").SerializeToString())
        for sink in (queued, direct):
            assert wait_until(lambda sink=sink: sink.texts == ["ok"])  # type: ignore[misc]
            assert sink.reasons() == [
                Rejection.MALFORMED,
                Rejection.MALFORMED,
                Rejection.WRONG_TYPE,
            ]
        assert "gz.msgs.Int32" in queued.rejections[2][1]
        assert node.stats.messages_wrong_type == 2
    finally:
        rogue.close()


def test_what_a_publisher_sends_after_its_goodbye_still_arrives(node: ZmqGzNode) -> None:
    """A one-shot publisher (``ign topic -p``) can announce its leaving (UNADVERTISE) before
    its last message is on the wire. Both subscriptions still get that message, then leave
    the address (``connections.LEAVE_AFTER``)."""
    topic = unique("goodbye")
    queued, direct = Sink(), Sink()
    node.subscribe(topic, queued, STRING, queue_size=10)
    node.subscribe(topic, direct, STRING)
    rogue = RoguePublisher(node.fqn(topic), STRING)
    try:
        while rogue.subscriptions < 2:
            assert rogue.wait_subscribed(10), "both sockets subscribe"
        assert node.topic_info(topic), "listings answer at once from now on (discovery is up)"
        rogue.peer.unadvertise()
        assert wait_until(lambda: node.topic_info(topic) == []), "the goodbye was heard"
        time.sleep(0.05)  # the message comes after it
        rogue.send(StringMsg(data="last words").SerializeToString())
        assert wait_until(lambda: bool(queued.texts and direct.texts))
        assert queued.texts == direct.texts == ["last words"]
        assert wait_until(lambda: node.stats.publishers_disconnected == 2)
    finally:
        rogue.close()


def test_publishers_that_fall_silent_are_disconnected_and_never_retried(node: ZmqGzNode) -> None:
    """A fake peer advertises 20 addresses that fail at once (libzmq retries them); once it
    is silent for 3 s its records expire and every address is disconnected: no connection
    attempt reaches the listeners any more."""
    topic = unique("ghost")
    node.subscribe(topic, Sink(), STRING, queue_size=10)
    node.subscribe(topic, Sink(), STRING)
    traps = TrapListeners(20)
    peer = FakePeer(node.fqn(topic), STRING, traps.addresses)
    try:
        assert wait_until(lambda: traps.accepted >= 40), "both sockets connect, and retry"
        peer.go_silent()
        assert wait_until(lambda: node.stats.publishers_disconnected == 2 * 20, 6)
        time.sleep(0.5)  # connection attempts already under way end
        settled = traps.accepted
        time.sleep(2.0)
        assert traps.accepted == settled
        assert node.topic_info(topic) == []
    finally:
        traps.close()


def test_only_tcp_addresses_are_taken_from_the_network(node: ZmqGzNode) -> None:
    topic = unique("ipc")
    node.subscribe(topic, Sink(), STRING, queue_size=10)
    peer = FakePeer(
        node.fqn(topic),
        STRING,
        ["ipc:///tmp/not-ours", "inproc://x", "tcp://127.0.0.1:0", "tcp://eth0;127.0.0.1:9"],
    )
    try:
        assert wait_until(lambda: node.stats.addresses_refused >= 4)
        assert node.topic_info(topic) == []
    finally:
        peer.go_silent()


def _settings(credentials: tuple[str, str] | None) -> TransportSettings:
    return dataclasses.replace(TransportSettings.from_env(), credentials=credentials)


@pytest.mark.parametrize(
    ("publisher", "subscriber", "flows"),
    [
        (("robot", "s3cret"), ("robot", "s3cret"), True),
        (("robot", "s3cret"), ("robot", "guess"), False),
        (("robot", "s3cret"), None, False),
    ],
)
def test_plain_authentication(
    publisher: tuple[str, str], subscriber: tuple[str, str] | None, flows: bool
) -> None:
    """docs/protocol-zmq-data.md §2.8.6: the PUB socket a PLAIN server, SUB sockets PLAIN clients.
    Without credentials the mechanisms differ and the handshake fails before ZAP is asked."""
    with (
        ZmqGzNode(settings=_settings(publisher)) as a,
        ZmqGzNode(settings=_settings(subscriber)) as b,
    ):
        topic = unique("auth")
        sink = Sink()
        b.subscribe(topic, sink, STRING, queue_size=10)
        pub = a.advertise(topic, STRING)
        assert wait_until(pub.has_connections)  # discovery is not authenticated
        deadline = time.monotonic() + (10 if flows else 2)
        while time.monotonic() < deadline and not sink.texts:
            pub.publish(StringMsg(data="secret"))
            time.sleep(0.05)
        assert bool(sink.texts) == flows
        if subscriber is not None and not flows:  # wrong credentials: both sides count them
            assert wait_until(lambda: a.stats.auth_failures > 0 and b.stats.auth_failures > 0)


_FQ_ABORT = """
import sys, time, zmq
sys.path.insert(0, {root!r})
from ros_gz_bridge_py.transport.zmq.connections import SubConnections
from ros_gz_bridge_py.transport.zmq.socket_owner import receive_message
ctx = zmq.Context()
pub = ctx.socket(zmq.PUB); pub.bind("tcp://127.0.0.1:*")
address = pub.getsockopt_string(zmq.LAST_ENDPOINT)
sub = ctx.socket(zmq.SUB); sub.setsockopt(zmq.SUBSCRIBE, b"")
read = []
def drain():
    while True:
        try:
            read.append(receive_message(sub))
        except zmq.Again:
            return
connections = SubConnections(sub, drain=drain, on_refused=print, count=lambda *a: None, what="t")
connections.connect(address)
time.sleep(0.3)
pub.send_multipart([b"topic", b"sender", b"payload", b"type"])
time.sleep(0.2)
assert sub.poll(100)  # zmq_poll takes the first frame out of the pipe
if sys.argv[1] == "ours":
    connections.disconnect(address)
else:
    sub.disconnect(address)
try:
    while True:
        sub.recv(zmq.NOBLOCK)
except zmq.Again:
    pass
print("survived", len(read))
"""


@pytest.mark.parametrize("how", ["plain", "ours"])
def test_disconnecting_after_a_poll_aborts_libzmq_unless_the_socket_is_drained_first(
    how: str,
) -> None:
    """The libzmq bug that kept the SUB socket from ever disconnecting (issue #2163, still in
    the libzmq pyzmq bundles): zmq_poll prefetches a message's first frame, a disconnect then
    drops the rest, and the next read aborts the process in fq.cpp. SubConnections.disconnect
    reads whole messages first."""
    root = str(Path(__file__).resolve().parents[4])
    script = textwrap.dedent(_FQ_ABORT).format(root=root)
    command = [sys.executable, "-c", script, how]
    done = subprocess.run(command, capture_output=True, text=True, timeout=30, check=False)
    if how == "plain":
        assert done.returncode != 0
        assert "fq.cpp" in done.stderr
    else:
        assert done.returncode == 0, done.stderr
        assert done.stdout.strip() == "survived 1"


def test_service_providers_that_go_are_disconnected_and_response_addresses_are_tcp(
    node: ZmqGzNode,
) -> None:
    """The requester disconnects from a provider whose records went away; a request whose
    response address is not ``tcp://`` is refused before its handler runs."""
    service = unique("srv")
    calls: list[bytes] = []

    def handler(request: bytes) -> tuple[bool, bytes]:
        calls.append(request)
        return True, request

    with ZmqGzNode() as provider:
        provider.advertise_service(service, STRING, STRING, handler)
        assert node.request(service, b"\x0a\x01x", STRING, STRING, 10) == (True, b"\x0a\x01x")
        assert node._services._requester_connected == {provider.replier_address}
        raw: zmq.Socket[bytes] = zmq.Context.instance().socket(zmq.ROUTER)
        raw.setsockopt(zmq.LINGER, 0)
        raw.setsockopt(zmq.ROUTER_MANDATORY, 1)
        raw.connect(provider.replier_address)
        request = ServiceRequest(
            provider.fqn(service), "ipc:///tmp/answer-here", "id", "node", "req", b"",
            STRING, STRING,
        )  # fmt: skip
        frames = encode_request(provider._io.replier_id, request)
        assert wait_until(lambda: _sent(raw, frames))
        assert wait_until(lambda: provider.stats.addresses_refused == 1)
        raw.close()
        assert len(calls) == 1
    assert wait_until(lambda: not node._services._requester_connected)


def _sent(sock: zmq.Socket[bytes], frames: list[Any]) -> bool:
    try:
        sock.send_multipart(frames, zmq.NOBLOCK)
    except zmq.ZMQError:  # not routable until the connection is up
        time.sleep(0.02)
        return False
    return True

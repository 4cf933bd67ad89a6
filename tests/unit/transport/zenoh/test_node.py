"""ZenohGzNode against a second process (``zenoh_peer.py``), in peer mode and through a router.

Every session listens/connects on explicit ``tcp/127.0.0.1`` ports with multicast scouting
off. The peer process runs its own ZenohGzNode plus raw Zenoh entities (plain subscriber,
hand-made puts and tokens) to play a gz process or a misbehaving one.
"""

from __future__ import annotations

import json
import queue
import subprocess
import sys
import threading
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
import zenoh

from ros_gz_bridge_py.errors import TransportTimeoutError
from ros_gz_bridge_py.msgs import GENERIC_TYPE, message_class
from ros_gz_bridge_py.transport.api import MessageInfo
from ros_gz_bridge_py.transport.zenoh.config import (
    OVERRIDE_ENV,
    endpoints_config,
    parse_overrides,
    session_config,
)
from ros_gz_bridge_py.transport.zenoh.node import ZenohGzNode
from testing.loopback import free_port
from testing.polling import wait_until

PEER_SCRIPT = Path(__file__).with_name("zenoh_peer.py")
ROOT = PEER_SCRIPT.parents[4]
STRING = "gz.msgs.StringMsg"
EMPTY = "gz.msgs.Empty"
StringMsg = message_class(STRING)
#: Upper bound of every wait; reaching it fails the test.
LIMIT = 10.0


def endpoint(port: int) -> str:
    return f"tcp/127.0.0.1:{port}"


class Peer:
    """The ``zenoh_peer.py`` process: JSON commands in, JSON events out."""

    def __init__(self, *args: str) -> None:
        self.proc = subprocess.Popen(
            [sys.executable, str(PEER_SCRIPT), *args],
            stdin=subprocess.PIPE,
            stdout=subprocess.PIPE,
            text=True,
            cwd=ROOT,
        )
        self._events: queue.Queue[dict[str, Any]] = queue.Queue()
        self._backlog: list[dict[str, Any]] = []
        threading.Thread(target=self._read, daemon=True).start()
        self.ready = self.expect("ready")

    def _read(self) -> None:
        assert self.proc.stdout is not None
        for line in self.proc.stdout:
            self._events.put(json.loads(line))

    def expect(self, event: str, **match: Any) -> dict[str, Any]:
        """The first event named ``event`` whose fields include ``match``."""

        def fits(item: dict[str, Any]) -> bool:
            return item["event"] == event and all(item.get(k) == v for k, v in match.items())

        for item in self._backlog:
            if fits(item):
                self._backlog.remove(item)
                return item
        deadline = time.monotonic() + LIMIT
        while True:
            try:
                item = self._events.get(timeout=max(0.0, deadline - time.monotonic()))
            except queue.Empty:
                pytest.fail(f"peer sent no {event} {match}; backlog {self._backlog}")
            if fits(item):
                return item
            self._backlog.append(item)

    def send(self, cmd: str, **fields: Any) -> dict[str, Any]:
        """Run one command in the peer and return its ``done`` event."""
        assert self.proc.stdin is not None
        self.proc.stdin.write(json.dumps({"cmd": cmd, **fields}) + "\n")
        self.proc.stdin.flush()
        return self.expect("done", cmd=cmd)

    def close(self) -> None:
        assert self.proc.stdin is not None
        self.proc.stdin.close()
        try:
            self.proc.wait(timeout=LIMIT)
        except subprocess.TimeoutExpired:
            self.proc.kill()
            self.proc.wait()


@pytest.fixture(scope="module")
def router_port() -> Iterator[int]:
    port = free_port()
    router = Peer("router", "--listen", endpoint(port))
    yield port
    router.close()


@pytest.fixture(scope="module", params=["peer", "client"])
def pair(request: pytest.FixtureRequest, router_port: int) -> Iterator[tuple[ZenohGzNode, Peer]]:
    """Our node and a peer process, directly connected or both clients of the router."""
    if request.param == "peer":
        port = free_port()
        node = ZenohGzNode(config=endpoints_config("peer", listen=[endpoint(port)]))
        peer = Peer("node", "--mode", "peer", "--connect", endpoint(port))
    else:
        node = ZenohGzNode(config=endpoints_config("client", connect=[endpoint(router_port)]))
        peer = Peer("node", "--mode", "client", "--connect", endpoint(router_port))
    yield node, peer
    peer.close()
    node.close()


def unique(name: str, node: ZenohGzNode) -> str:
    return f"/{name}_{node.node_uuid[:8]}"


def test_publish_to_peer_subscriptions(pair: tuple[ZenohGzNode, Peer]) -> None:
    node, peer = pair
    topic = unique("to_peer", node)
    publisher = node.advertise(topic, STRING)
    peer.send("subscribe", topic=topic, type=STRING)
    peer.send("subscribe", topic=topic, type="")
    assert wait_until(publisher.has_connections)
    publisher.publish(StringMsg(data="hello"))
    for _ in range(2):
        event = peer.expect("msg", topic=topic)
        assert event["type"] == STRING
        assert StringMsg.FromString(bytes.fromhex(event["data"])).data == "hello"


@pytest.mark.parametrize("wire_type", [STRING, "ignition.msgs.StringMsg"])
def test_subscribe_to_peer_publisher(pair: tuple[ZenohGzNode, Peer], wire_type: str) -> None:
    node, peer = pair
    topic = unique("from_peer", node)
    typed: queue.Queue[tuple[Any, MessageInfo]] = queue.Queue()
    raw: queue.Queue[tuple[bytes, MessageInfo]] = queue.Queue()
    node.subscribe_typed(topic, StringMsg, lambda m, i: typed.put((m, i)), msg_type=wire_type)
    node.subscribe(topic, lambda p, i: raw.put((p, i)), queue_size=4)
    peer.send("advertise", topic=topic, type=wire_type)
    assert peer.send("wait_connected", topic=topic)["ok"]
    peer.send("publish", topic=topic, text="hi")
    msg, info = typed.get(timeout=LIMIT)
    assert msg.data == "hi"
    # A publisher of either spelling puts gz.msgs here: our MS tokens say gz.msgs, as every
    # Zenoh peer (Jetty or later) does.
    assert (info.topic, info.msg_type, info.intra_process) == (topic, STRING, False)
    payload, raw_info = raw.get(timeout=LIMIT)
    assert StringMsg.FromString(payload).data == "hi"
    assert raw_info.msg_type == STRING
    # A put in the other spelling is taken too, and said to be of that spelling.
    other = "ignition.msgs.StringMsg" if wire_type == STRING else STRING
    data = StringMsg(data="respelled").SerializeToString().hex()
    peer.send("raw_put", topic=topic, payload=data, attachment=other)
    msg, info = typed.get(timeout=LIMIT)
    assert (msg.data, info.msg_type) == ("respelled", other)


def test_calls_to_peer_service(pair: tuple[ZenohGzNode, Peer]) -> None:
    node, peer = pair
    service, one_way = unique("srv", node), unique("oneway", node)
    peer.send("serve", service=service, req=STRING, rep=STRING)
    peer.send("serve", service=one_way, req=STRING, rep=EMPTY)
    assert node.request(service, b"ping", STRING, STRING, LIMIT) == (True, b"re:ping")
    assert node.request(service, b"fail", STRING, STRING, LIMIT) == (False, b"")
    assert node.request(one_way, b"note", STRING, EMPTY, LIMIT) == (True, b"")
    assert peer.expect("request", service=one_way)["data"] == b"note".hex()
    with pytest.raises(TransportTimeoutError):
        node.request(service, b"slow", STRING, STRING, 0.2)
    # Types must match the provider's token exactly, else the call waits until its timeout.
    with pytest.raises(TransportTimeoutError):
        node.request(service, b"ping", EMPTY, STRING, 0.2)


def test_peer_calls_our_service(pair: tuple[ZenohGzNode, Peer]) -> None:
    node, peer = pair
    service = unique("ours", node)
    node.advertise_service(service, STRING, STRING, lambda req: (req != b"no", req[::-1]))
    peer.send("call", service=service, req=STRING, rep=STRING, data=b"abc".hex(), timeout=LIMIT)
    assert peer.expect("reply", service=service)["data"] == b"cba".hex()
    peer.send("call", service=service, req=STRING, rep=STRING, data=b"no".hex(), timeout=LIMIT)
    assert peer.expect("reply", service=service)["ok"] is False


def test_listing_shows_peer_entities(pair: tuple[ZenohGzNode, Peer]) -> None:
    node, peer = pair
    topic, service = unique("listed", node), unique("listed_srv", node)
    peer.send("advertise", topic=topic, type=STRING)
    peer.send("serve", service=service, req=STRING, rep=EMPTY)
    infos = node.wait_for_publishers(topic, LIMIT, STRING)
    assert [i.process_uuid for i in infos] == [peer.ready["process_uuid"]]
    assert topic in node.topic_list()
    assert wait_until(lambda: service in node.service_list())
    [provider] = node.service_info(service)
    assert (provider.request_type, provider.response_type) == (STRING, EMPTY)
    assert provider.msg_type == f"{STRING}&{EMPTY}"


def test_no_put_before_a_subscriber_token(pair: tuple[ZenohGzNode, Peer]) -> None:
    node, peer = pair
    topic, marker = unique("gated", node), unique("gated_marker", node)
    publisher = node.advertise(topic, STRING)
    # A plain Zenoh subscriber, then a token declared after it on the same link: once we
    # see the token, the subscriber is known here too.
    peer.send("raw_subscribe", topic=topic)
    peer.send("advertise", topic=marker, type=STRING)
    assert node.wait_for_publishers(marker, LIMIT)
    assert not publisher.has_connections()
    publisher.publish(StringMsg(data="unseen"))
    peer.send("ms_token", topic=topic, type=GENERIC_TYPE)
    assert wait_until(publisher.has_connections)
    publisher.publish(StringMsg(data="seen"))
    first = peer.expect("raw")
    assert StringMsg.FromString(bytes.fromhex(first["data"])).data == "seen"


def test_bad_input_is_counted_and_skipped(pair: tuple[ZenohGzNode, Peer]) -> None:
    node, peer = pair
    topic = unique("bad", node)
    received: queue.Queue[Any] = queue.Queue()
    before = node.stats
    node.subscribe_typed(topic, StringMsg, lambda m, _i: received.put(m.data))
    peer.send("advertise", topic=topic, type=STRING)
    assert peer.send("wait_connected", topic=topic)["ok"]
    good = StringMsg(data="x").SerializeToString().hex()
    peer.send("raw_put", topic=topic, payload=good, attachment=None)
    peer.send("raw_put", topic=topic, payload=good, attachment="gz.msgs.Int32")
    peer.send("raw_put", topic=topic, payload=b"\x0a\xff".hex(), attachment=STRING)
    peer.send("raw_token", key="@gz/not/a/token")
    peer.send("publish", topic=topic, text="good")
    assert received.get(timeout=LIMIT) == "good"
    assert received.empty()
    after = node.stats
    assert after.frames_malformed == before.frames_malformed + 1
    assert after.messages_wrong_type == before.messages_wrong_type + 1
    assert after.payloads_undecodable == before.payloads_undecodable + 1
    assert wait_until(lambda: node.stats.datagrams_malformed > before.datagrams_malformed)
    assert node.stats.io_errors == 0


def test_local_delivery_once_and_ignore_local(pair: tuple[ZenohGzNode, Peer]) -> None:
    node, peer = pair
    topic = unique("local", node)
    got: list[tuple[str, bool]] = []
    ignored: list[str] = []
    publisher = node.advertise(topic, STRING)
    # A remote subscriber makes us put on Zenoh too; our own subscriptions must not get it back.
    peer.send("subscribe", topic=topic, type=STRING)
    assert wait_until(publisher.has_connections)
    node.subscribe_typed(topic, StringMsg, lambda m, i: got.append((m.data, i.intra_process)))
    node.subscribe_typed(topic, StringMsg, lambda m, _i: ignored.append(m.data), ignore_local=True)
    publisher.publish(StringMsg(data="one"))
    peer.expect("msg", topic=topic)
    publisher.publish(StringMsg(data="two"))
    peer.expect("msg", topic=topic)
    assert got == [("one", True), ("two", True)]
    assert ignored == []


@pytest.mark.parametrize("pair", ["client"], indirect=True)
def test_close_leaves_no_threads_or_tokens(
    pair: tuple[ZenohGzNode, Peer], router_port: int
) -> None:
    _, peer = pair
    threads_before = set(threading.enumerate())
    node = ZenohGzNode(config=endpoints_config("client", connect=[endpoint(router_port)]))
    topic, service = unique("closing", node), unique("closing_srv", node)
    node.advertise(topic, STRING)
    node.subscribe(topic, lambda _p, _i: None, queue_size=2)
    node.advertise_service(service, STRING, STRING, lambda req: (True, req))
    assert peer.send("wait_publishers", topic=topic, present=True)["ok"]
    assert peer.send("wait_services", service=service, present=True)["ok"]
    node.close()
    node.close()
    assert peer.send("wait_publishers", topic=topic, present=False)["ok"]
    assert peer.send("wait_services", service=service, present=False)["ok"]
    assert wait_until(lambda: set(threading.enumerate()) <= threads_before)


def mode_of(config: zenoh.Config) -> Any:
    return json.loads(config.get_json("mode"))


def test_override_string_is_split_as_gz_does() -> None:
    text = ' mode = "client" ;\tconnect/endpoints=["tcp/127.0.0.1:1"];novalue; =1;a=b=c;'
    assert parse_overrides(text) == [
        ("mode", '"client"'),
        ("connect/endpoints", '["tcp/127.0.0.1:1"]'),
        ("a", "b=c"),
    ]


def test_config_file_then_env_overrides_then_caller(
    tmp_path: Path, caplog: pytest.LogCaptureFixture
) -> None:
    config_file = tmp_path / "zenoh.json5"
    config_file.write_text('{ mode: "client" }')
    env = {"ZENOH_CONFIG": str(config_file)}
    assert mode_of(session_config(env=env)) == "client"
    env[OVERRIDE_ENV] = 'mode="router"; no/such/key=1'
    assert mode_of(session_config(env=env)) == "router"
    assert "no/such/key" in caplog.text
    config = session_config(overrides={"mode": '"peer"'}, env=env)
    assert mode_of(config) == "peer"


@pytest.mark.parametrize("content", [None, "not json5 {{{"])
def test_unusable_config_file_falls_back_to_default(
    tmp_path: Path, caplog: pytest.LogCaptureFixture, content: str | None
) -> None:
    path = tmp_path / "zenoh.json5"
    if content is not None:
        path.write_text(content)
    config = session_config(env={"ZENOH_CONFIG": str(path)})
    assert config.get_json("mode") == zenoh.Config().get_json("mode")
    assert str(path) in caplog.text

"""The sans-IO discovery engine with an injected clock (docs/protocol-zmq-discovery.md
§2.4-§2.7)."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import replace
from typing import Any

import pytest

from ros_gz_bridge_py.transport.api import Scope
from ros_gz_bridge_py.transport.wire_types import RemoteSubscriber
from ros_gz_bridge_py.transport.zmq import discovery_memo
from ros_gz_bridge_py.transport.zmq.discovery import (
    ACTIVITY_INTERVAL,
    HEARTBEAT_INTERVAL,
    SILENCE_INTERVAL,
    DiscoveryEngine,
)
from ros_gz_bridge_py.transport.zmq.discovery_events import (
    Outgoing,
    PublisherAdded,
    PublisherRemoved,
    SubscriberAdded,
    SubscriberRemoved,
)
from ros_gz_bridge_py.transport.zmq.wire import (
    DiscoveryMessage,
    DiscoveryType,
    MessagePublisher,
    PublisherRecord,
    decode_discovery,
    encode_discovery,
)
from tests.unit.transport.peers import ME, MY_NODE, PEER, PEER_NODE, TOPIC, record


def datagram(kind: DiscoveryType, process: str = PEER, **fields: object) -> bytes:
    return encode_discovery(DiscoveryMessage(kind, process, **fields))  # type: ignore[arg-type]


def sent(out: list[Outgoing]) -> list[DiscoveryMessage]:
    return [decode_discovery(o.data) for o in out]


def test_heartbeat_schedule_and_readvertise() -> None:
    engine = DiscoveryEngine(ME, 100.0)
    engine.advertise(record(ME))
    engine.advertise(record(ME, scope=Scope.PROCESS))
    out, _ = engine.tick(100.0)
    assert [m.type for m in sent(out)] == [DiscoveryType.HEARTBEAT, DiscoveryType.ADVERTISE]
    assert engine.tick(100.5) == ([], [])
    assert engine.next_deadline() <= 100.0 + HEARTBEAT_INTERVAL
    out, _ = engine.tick(101.0)
    assert [m.type for m in sent(out)] == [DiscoveryType.HEARTBEAT, DiscoveryType.ADVERTISE]


def test_an_idle_engine_wakes_for_heartbeats_and_rarely_else_yet_expires_in_time() -> None:
    """The silence check is due when the peer heard from longest ago can have gone silent (about
    once per SILENCE_INTERVAL while it beats), not every ACTIVITY_INTERVAL; a silent peer is
    still forgotten within ACTIVITY_INTERVAL after SILENCE_INTERVAL, as gz-transport's check
    every 100 ms forgets it."""
    engine = DiscoveryEngine(ME, 0.0)
    engine.tick(0.0)  # the first heartbeat
    assert engine.next_deadline() == HEARTBEAT_INTERVAL  # no peer: nothing else is due
    engine.datagram_received(datagram(DiscoveryType.ADVERTISE, pub=record()), "127.0.0.1", 0.5)
    heartbeat = datagram(DiscoveryType.HEARTBEAT)
    wakes, beats, now = 0, [1.5, 2.5, 3.5, 4.5, 5.5, 6.5, 7.5, 8.5], 0.0
    while beats:  # an I/O loop: the peer's beats arrive between the engine's deadlines
        now = min(engine.next_deadline(), beats[0])
        if now == beats[0]:
            engine.datagram_received(heartbeat, "127.0.0.1", beats.pop(0))
            continue
        wakes += 1
        assert engine.tick(now)[1] == []
    assert wakes <= 8 + 3  # our 8 heartbeats and a silence check per 3 s (was 80 checks)
    last, expired = 8.5, list[object]()  # the peer's last beat; it falls silent
    while not expired:
        now = engine.next_deadline()
        assert now <= last + SILENCE_INTERVAL + ACTIVITY_INTERVAL + 1e-9
        expired = list(engine.tick(now)[1])
    assert expired == [PublisherRemoved(record())]
    assert now > last + SILENCE_INTERVAL
    assert engine.next_deadline() - now <= HEARTBEAT_INTERVAL  # heartbeats only again


def test_advertise_adds_once_and_silence_expires() -> None:
    engine = DiscoveryEngine(ME, 0.0)
    ad = datagram(DiscoveryType.ADVERTISE, pub=record())
    assert engine.datagram_received(ad, "127.0.0.1", 0.0)[1] == [PublisherAdded(record())]
    assert engine.datagram_received(ad, "127.0.0.1", 1.0)[1] == []
    assert engine.remote_publishers(TOPIC) == [record()]
    assert engine.tick(1.0 + SILENCE_INTERVAL - 0.01)[1] == []
    assert engine.tick(1.0 + SILENCE_INTERVAL + 0.2)[1] == [PublisherRemoved(record())]
    assert engine.remote_publishers(TOPIC) == []
    assert engine.counts["peers_expired"] == 1


def test_heartbeats_keep_a_peer_alive() -> None:
    engine = DiscoveryEngine(ME, 0.0)
    engine.datagram_received(datagram(DiscoveryType.ADVERTISE, pub=record()), "127.0.0.1", 0.0)
    for second in range(1, 10):
        engine.datagram_received(datagram(DiscoveryType.HEARTBEAT), "127.0.0.1", float(second))
        assert engine.tick(second + 0.5)[1] == []
    assert engine.remote_publishers(TOPIC) == [record()]


def test_restart_with_new_uuid_and_move_to_new_address() -> None:
    engine = DiscoveryEngine(ME, 0.0)
    engine.datagram_received(datagram(DiscoveryType.ADVERTISE, pub=record()), "127.0.0.1", 0.0)
    moved = record(address="tcp://127.0.0.1:6000")
    events = engine.datagram_received(
        datagram(DiscoveryType.ADVERTISE, pub=moved), "127.0.0.1", 0.5
    )[1]
    assert events == [PublisherRemoved(record()), PublisherAdded(moved)]
    restarted = PublisherRecord(
        TOPIC,
        moved.address,
        "55555555-5555-5555-5555-555555555555",
        PEER_NODE,
        Scope.ALL,
        moved.msg,
    )
    events = engine.datagram_received(
        datagram(DiscoveryType.ADVERTISE, restarted.process_uuid, pub=restarted), "127.0.0.1", 1.0
    )[1]
    assert events == [PublisherAdded(restarted)]
    assert engine.tick(3.6)[1] == [PublisherRemoved(moved)]
    assert engine.remote_publishers(TOPIC) == [restarted]


def test_unadvertise_and_bye() -> None:
    engine = DiscoveryEngine(ME, 0.0)
    engine.datagram_received(datagram(DiscoveryType.ADVERTISE, pub=record()), "127.0.0.1", 0.0)
    events = engine.datagram_received(
        datagram(DiscoveryType.UNADVERTISE, pub=record()), "127.0.0.1", 0.1
    )[1]
    assert events == [PublisherRemoved(record())]
    engine.datagram_received(datagram(DiscoveryType.ADVERTISE, pub=record()), "127.0.0.1", 0.2)
    assert engine.datagram_received(datagram(DiscoveryType.BYE), "127.0.0.1", 0.3)[1] == [
        PublisherRemoved(record())
    ]


def test_subscribe_is_answered_with_scope_filtering() -> None:
    engine = DiscoveryEngine(ME, 0.0, local_ips={"10.0.0.5"})
    engine.advertise(record(ME))
    engine.advertise(record(ME, address="tcp://10.0.0.5:1", scope=Scope.HOST))
    engine.advertise(record(ME, address="inproc", scope=Scope.PROCESS))
    ask = datagram(DiscoveryType.SUBSCRIBE, topic=TOPIC)
    local = sent(engine.datagram_received(ask, "10.0.0.5", 0.0)[0])
    assert [m.pub.scope for m in local if m.pub] == [Scope.ALL, Scope.HOST]
    remote = sent(engine.datagram_received(ask, "10.0.0.9", 0.0)[0])
    assert [m.pub.scope for m in remote if m.pub] == [Scope.ALL]
    other = datagram(DiscoveryType.SUBSCRIBE, topic="@/p@/other")
    assert engine.datagram_received(other, "10.0.0.5", 0.0)[0] == []


def test_received_scope_filter() -> None:
    engine = DiscoveryEngine(ME, 0.0, local_ips={"10.0.0.5"})
    host = record(scope=Scope.HOST)
    assert (
        engine.datagram_received(datagram(DiscoveryType.ADVERTISE, pub=host), "10.0.0.9", 0.0)[1]
        == []
    )
    assert engine.datagram_received(datagram(DiscoveryType.ADVERTISE, pub=host), "127.0.0.2", 0.0)[
        1
    ] == [PublisherAdded(host)]
    process = record(scope=Scope.PROCESS, address="tcp://x:1")
    assert (
        engine.datagram_received(datagram(DiscoveryType.ADVERTISE, pub=process), "127.0.0.1", 0.0)[
            1
        ]
        == []
    )


def test_new_connection_contents() -> None:
    """§2.4, docs/protocol-zmq-data.md §2.8.1 step 5: the publisher's record, our uuids, ctrl =
    publisher's process uuid."""
    engine = DiscoveryEngine(ME, 0.0)
    (message,) = sent(engine.connect(record(), MY_NODE))
    assert message.type == DiscoveryType.NEW_CONNECTION
    assert message.process_uuid == ME
    assert message.pub == PublisherRecord(
        TOPIC, "tcp://127.0.0.1:5000", ME, MY_NODE, Scope.ALL,
        MessagePublisher("gz.msgs.StringMsg", ctrl=PEER),
    )  # fmt: skip


def test_remote_subscribers_from_new_and_end_connection() -> None:
    engine = DiscoveryEngine(ME, 0.0)
    engine.advertise(record(ME))
    theirs = PublisherRecord(
        TOPIC, "a", PEER, PEER_NODE, Scope.ALL, MessagePublisher("gz.msgs.StringMsg", ctrl=ME)
    )
    events = engine.datagram_received(
        datagram(DiscoveryType.NEW_CONNECTION, pub=theirs), "127.0.0.1", 0.0
    )[1]
    assert events == [SubscriberAdded(TOPIC, PEER, PEER_NODE, "gz.msgs.StringMsg")]
    assert engine.remote_subscribers(TOPIC) == (
        RemoteSubscriber(PEER, PEER_NODE, frozenset({"gz.msgs.StringMsg"})),
    )
    not_mine = PublisherRecord(
        TOPIC, "a", PEER, "n2", Scope.ALL, MessagePublisher("t", ctrl="someone")
    )
    assert (
        engine.datagram_received(
            datagram(DiscoveryType.NEW_CONNECTION, pub=not_mine), "127.0.0.1", 0.0
        )[1]
        == []
    )
    # END_CONNECTION as the subscriber sends it: our ctrl, then an empty ctrl.
    peer = DiscoveryEngine(PEER, 0.0)
    ends = peer.disconnect(TOPIC, PEER_NODE, "a", [ME])
    assert [m.pub.msg.ctrl for m in sent(ends) if m.pub and m.pub.msg] == [ME, ""]
    events = engine.datagram_received(ends[0].data, "127.0.0.1", 0.1)[1]
    assert events == [SubscriberRemoved(TOPIC, PEER, PEER_NODE)]
    assert engine.datagram_received(ends[1].data, "127.0.0.1", 0.1)[1] == []
    assert engine.remote_subscribers(TOPIC) == ()


@pytest.mark.parametrize("goes", ["silent", "bye"])
def test_a_gone_process_is_no_remote_subscriber_any_more(goes: str) -> None:
    """A subscriber killed without END_CONNECTION (SIGKILL, a crash) was kept for good: the
    bridge's ROS->Gazebo channel showed "flowing" to nobody and a lazy one stayed open (found
    by a new user restarting a simulator)."""
    engine = DiscoveryEngine(ME, 0.0)
    engine.advertise(record(ME))
    theirs = PublisherRecord(
        TOPIC, "a", PEER, PEER_NODE, Scope.ALL, MessagePublisher("gz.msgs.StringMsg", ctrl=ME)
    )
    engine.datagram_received(datagram(DiscoveryType.NEW_CONNECTION, pub=theirs), "127.0.0.1", 0.0)
    assert engine.registered_topics() == [TOPIC]
    if goes == "bye":
        events = engine.datagram_received(datagram(DiscoveryType.BYE), "127.0.0.1", 0.5)[1]
    else:
        events = engine.tick(SILENCE_INTERVAL + 0.2)[1]
    assert events == [SubscriberRemoved(TOPIC, PEER, PEER_NODE)]
    assert (engine.remote_subscribers(TOPIC), engine.registered_topics()) == ((), [])


def test_a_subscriber_that_unsubscribes_leaves_no_sighting_behind() -> None:
    """A typed subscriber that took our type and went (END_CONNECTION) is not one that
    SUBSCRIBEd and never took it: the explanations called it "did not take ... it expects
    another message type" for the seconds until its process expired."""
    engine = DiscoveryEngine(ME, 0.0)
    engine.advertise(record(ME))
    engine.datagram_received(datagram(DiscoveryType.SUBSCRIBE, topic=TOPIC), "127.0.0.1", 0.0)
    assert engine.subscribe_sightings() == {TOPIC: {PEER: "127.0.0.1"}}
    theirs = PublisherRecord(
        TOPIC, "a", PEER, PEER_NODE, Scope.ALL, MessagePublisher("gz.msgs.StringMsg", ctrl=ME)
    )
    engine.datagram_received(datagram(DiscoveryType.NEW_CONNECTION, pub=theirs), "127.0.0.1", 0.0)
    ends = DiscoveryEngine(PEER, 0.0).disconnect(TOPIC, PEER_NODE, "a", [ME])
    engine.datagram_received(ends[0].data, "127.0.0.1", 0.1)
    assert engine.subscribe_sightings() == {}


def test_own_and_foreign_versions_and_garbage_are_dropped() -> None:
    engine = DiscoveryEngine(ME, 0.0)
    assert engine.datagram_received(
        datagram(DiscoveryType.ADVERTISE, ME, pub=record(ME)), "127.0.0.1", 0.0
    ) == ([], [])
    old = datagram(DiscoveryType.ADVERTISE, version=110, pub=record())
    assert engine.datagram_received(old, "127.0.0.1", 0.0) == ([], [])
    assert engine.datagram_received(b"\x01\x00\x08", "127.0.0.1", 0.0) == ([], [])
    no_pub = datagram(DiscoveryType.ADVERTISE)
    assert engine.datagram_received(no_pub, "127.0.0.1", 0.0) == ([], [])
    assert engine.counts["wrong_version"] == 1
    assert engine.counts["malformed"] == 2
    assert engine.remote_publishers(TOPIC) == []


def test_subscribers_req_answered_with_local_subscriptions() -> None:
    engine = DiscoveryEngine(ME, 0.0)
    mine = PublisherRecord(
        TOPIC,
        "tcp://me:1",
        ME,
        MY_NODE,
        Scope.ALL,
        MessagePublisher("google.protobuf.Message", ctrl=""),
    )
    engine.add_local_subscriber(mine)
    (reply,) = sent(
        engine.datagram_received(datagram(DiscoveryType.SUBSCRIBERS_REQ), "127.0.0.1", 0.0)[0]
    )
    assert (reply.type, reply.pub) == (DiscoveryType.SUBSCRIBERS_REP, mine)
    engine.remove_local_subscriber(mine)
    assert (
        engine.datagram_received(datagram(DiscoveryType.SUBSCRIBERS_REQ), "127.0.0.1", 0.0)[0] == []
    )


def test_relays() -> None:
    """§2.7: unicast copies with relay set; a relayed message is re-multicast, not processed."""
    engine = DiscoveryEngine(ME, 0.0, relays=["10.1.1.1"])
    out = engine.subscribe(TOPIC)
    assert [(o.relay_ip, decode_discovery(o.data).relay) for o in out] == [
        (None, False),
        ("10.1.1.1", True),
    ]
    relayed = datagram(DiscoveryType.ADVERTISE, relay=True, pub=record())
    out, events = engine.datagram_received(relayed, "10.2.2.2", 0.0)
    assert events == []
    (again,) = out
    assert again.relay_ip is None
    assert (decode_discovery(again.data).relay, decode_discovery(again.data).no_relay) == (
        False,
        True,
    )
    # Sender became a relay, and a plain multicast message is forwarded to both relays.
    out, events = engine.datagram_received(
        datagram(DiscoveryType.ADVERTISE, pub=record()), "127.0.0.1", 0.0
    )
    assert events == [PublisherAdded(record())]
    assert sorted(o.relay_ip for o in out if o.relay_ip) == ["10.1.1.1", "10.2.2.2"]
    # Processed after it came back with no_relay: not forwarded again.
    back = datagram(DiscoveryType.HEARTBEAT, no_relay=True)
    assert engine.datagram_received(back, "127.0.0.1", 0.0)[0] == []


def test_bye_unadvertises_everything() -> None:
    engine = DiscoveryEngine(ME, 0.0)
    engine.advertise(record(ME))
    assert [m.type for m in sent(engine.bye())] == [DiscoveryType.UNADVERTISE, DiscoveryType.BYE]
    assert list(engine.all_publishers()) == []


def test_only_tcp_addresses_are_taken_from_advertisements() -> None:
    """issue 14: a datagram must not make us connect to a unix socket or an in-process
    endpoint; ``tcp://host:port`` only."""
    engine = DiscoveryEngine(ME, 0.0)
    refused = [
        "ipc:///tmp/socket",
        "inproc://zeromq.zap.01",
        "tcp://127.0.0.1:0",
        "tcp://127.0.0.1:70000",
        "tcp://eth0;127.0.0.1:5",
        "tcp://127.0.0.1",
        "",
    ]
    for address in refused:
        ad = datagram(DiscoveryType.ADVERTISE, pub=record(address=address))
        assert engine.datagram_received(ad, "127.0.0.1", 0.0) == ([], [])
    assert engine.counts["addresses_refused"] == len(refused)
    for address in ("tcp://127.0.0.1:5000", "tcp://robot-1.local:6000", "tcp://[::1]:7000"):
        ad = datagram(DiscoveryType.ADVERTISE, pub=record(address=address))
        events = engine.datagram_received(ad, "127.0.0.1", 0.0)[1]
        assert events[-1] == PublisherAdded(record(address=address))  # (after the moved one)


def test_a_publisher_that_readvertises_rarely_stays_known() -> None:
    """gz-transport after 15 re-ADVERTISEs only on a change, for a new peer, or every tenth
    heartbeat: heartbeats alone must keep its records (docs/protocol-zmq-discovery.md §2.5)."""
    engine = DiscoveryEngine(ME, 0.0)
    engine.datagram_received(datagram(DiscoveryType.ADVERTISE, pub=record()), "127.0.0.1", 0.0)
    for second in range(1, 25):
        engine.datagram_received(datagram(DiscoveryType.HEARTBEAT), "127.0.0.1", float(second))
        assert engine.tick(second + 0.5)[1] == []
    assert engine.remote_publishers(TOPIC) == [record()]


def test_fields_added_by_newer_lines_are_ignored() -> None:
    """Additive fields (a node id in SUBSCRIBE, a snapshot in SUBSCRIBERS_REP, anything a
    later gz-transport adds) are skipped as protobuf skips unknown fields."""
    engine = DiscoveryEngine(ME, 0.0)
    extra = bytes([0xA2, 0x06, 0x04]) + b"node"  # field 100, length-delimited: unknown to us
    subscribe = datagram(DiscoveryType.SUBSCRIBE, topic=TOPIC)
    body = subscribe[2:] + extra
    widened = len(body).to_bytes(2, "little") + body
    engine.advertise(record(ME))
    out, events = engine.datagram_received(widened, "127.0.0.1", 0.0)
    assert events == []
    assert [m.type for m in sent(out)] == [DiscoveryType.ADVERTISE]
    assert engine.counts["malformed"] == 0


def test_repeated_datagrams_are_encoded_and_decoded_once(monkeypatch: pytest.MonkeyPatch) -> None:
    """Every second brings the same HEARTBEAT and ADVERTISE bytes from each process: the engine
    encodes its own once and decodes each it hears once; what it does with them is unchanged."""
    calls = {"encode": 0, "decode": 0}

    def counting(name: str, real: Callable[..., Any]) -> Callable[..., Any]:
        def call(*args: Any) -> Any:
            calls[name] += 1
            return real(*args)

        return call

    monkeypatch.setattr(discovery_memo, "encode_discovery", counting("encode", encode_discovery))
    monkeypatch.setattr(discovery_memo, "decode_discovery", counting("decode", decode_discovery))
    engine = DiscoveryEngine(ME, 0.0)
    engine.advertise(record(ME))
    heard = datagram(DiscoveryType.ADVERTISE, pub=record())
    firsts = []
    for second in range(5):
        out, _ = engine.tick(float(second))
        firsts.append([o.data for o in out])
        _, events = engine.datagram_received(heard, "127.0.0.1", second + 0.5)
        assert [type(e) for e in events] == ([PublisherAdded] if second == 0 else [])
        for own in out:  # the multicast loops our own datagrams back
            assert engine.datagram_received(own.data, "127.0.0.1", second + 0.5) == ([], [])
    assert all(first == firsts[0] for first in firsts)
    assert [m.type for m in sent([Outgoing(d) for d in firsts[0]])] == [
        DiscoveryType.HEARTBEAT,
        DiscoveryType.ADVERTISE,
    ]
    assert calls == {"encode": 2, "decode": 1 + 2}  # ours: HEARTBEAT, ADVERTISE; and the peer's
    assert engine.remote_publishers(TOPIC) == [record()]
    # a record withdrawn and advertised anew under another address is sent as it now is
    engine.unadvertise(record(ME))
    moved = replace(record(ME), address="tcp://127.0.0.1:4")
    engine.advertise(moved)
    out, _ = engine.tick(5.0)
    assert sent(out)[1].pub == moved


def test_the_decoded_memo_is_bounded(monkeypatch: pytest.MonkeyPatch) -> None:
    """Distinct datagrams (a hostile sender varies each one) never grow the memo past its
    bound, and large ones are not kept: each is still judged."""
    monkeypatch.setattr(discovery_memo, "DECODED_KEPT", 8)
    engine = DiscoveryEngine(ME, 0.0)
    for i in range(50):
        engine.datagram_received(datagram(DiscoveryType.HEARTBEAT, f"peer-{i}"), "127.0.0.1", 0.0)
        assert len(engine.memo.decoded()) <= 8
    big = replace(record(), topic="@/p@/" + "x" * discovery_memo.DECODED_SIZE)
    engine.datagram_received(datagram(DiscoveryType.ADVERTISE, pub=big), "127.0.0.1", 0.0)
    assert all(len(data) <= discovery_memo.DECODED_SIZE for data in engine.memo.decoded())
    assert engine.remote_publishers(big.topic) == [big]
    assert len(engine.processes()) == 51


def test_a_second_spelling_is_repeated_only_while_a_peer_may_use_it() -> None:
    """Our publisher is announced under both spellings when made and in answer to a SUBSCRIBE;
    the second announcement is repeated each second only while a live peer uses its spelling
    or has not shown its line yet."""
    respelled = "55555555-5555-5555-5555-555555555555"
    ours = record(ME)  # gz.msgs.StringMsg
    second = replace(ours, node_uuid=respelled, msg=MessagePublisher("ignition.msgs.StringMsg"))
    engine = DiscoveryEngine(ME, 0.0, respelled_nodes=[respelled])
    assert [m.pub for m in sent(engine.advertise(ours) + engine.advertise(second))] == [
        ours,
        second,
    ]

    def repeated(now: float) -> list[PublisherRecord | None]:
        out, _ = engine.tick(now)
        return [m.pub for m in sent(out) if m.type == DiscoveryType.ADVERTISE]

    assert repeated(0.0) == [ours]  # no peer
    subscribe = datagram(DiscoveryType.SUBSCRIBE, topic=TOPIC)
    answer, _ = engine.datagram_received(subscribe, "127.0.0.1", 0.5)
    assert [m.pub for m in sent(answer)] == [ours, second]
    assert repeated(1.0) == [ours, second]  # a peer whose line is not known yet
    modern = datagram(DiscoveryType.HEARTBEAT, pub=record())  # gz-transport 13+: gz.msgs
    engine.datagram_received(modern, "127.0.0.1", 1.5)
    assert repeated(2.0) == [ours]
    fortress = datagram(DiscoveryType.HEARTBEAT, "66666666-6666-6666-6666-666666666666")
    engine.datagram_received(fortress, "127.0.0.1", 2.5)  # no record: ignition.msgs
    assert repeated(3.0) == [ours, second]
    repeated(6.0)  # both peers silent for over 3 s: forgotten after this second's repeats
    assert engine.processes() == []
    assert repeated(7.0) == [ours]

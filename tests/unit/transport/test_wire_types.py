"""Which spelling each message is sent in (docs/protocol-lines.md §9), without sockets."""

from __future__ import annotations

from ros_gz_bridge_py.msgs.names import GENERIC_TYPE, Spelling
from ros_gz_bridge_py.transport.wire_types import (
    PeerSpellings,
    RemoteSubscriber,
    SubscriberBook,
    WireTypeCache,
    wire_types,
)
from ros_gz_bridge_py.transport.zmq.discovery import DiscoveryEngine
from ros_gz_bridge_py.transport.zmq.wire import DiscoveryMessage, DiscoveryType, encode_discovery
from tests.unit.transport.peers import record

GZ, IGN = "gz.msgs.Twist", "ignition.msgs.Twist"
NAMES = (GZ, IGN)


def sub(process: str, *types: str) -> RemoteSubscriber:
    return RemoteSubscriber(process, f"{process}-node", frozenset(types))


def test_typed_subscribers_get_their_spelling_generic_ones_their_lines() -> None:
    lines = {"fortress": Spelling.IGNITION, "harmonic": Spelling.GZ}.get
    assert wire_types(NAMES, [sub("fortress", IGN)], lines) == {IGN}
    assert wire_types(NAMES, [sub("harmonic", GZ)], lines) == {GZ}
    # A generic subscriber registers with both announcements (ZeroMQ) or says so (Zenoh).
    assert wire_types(NAMES, [sub("fortress", GZ, IGN)], lines) == {IGN}
    assert wire_types(NAMES, [sub("harmonic", GENERIC_TYPE)], lines) == {GZ}
    # Unknown line: the publisher's own spelling; another type: nothing for it.
    assert wire_types((IGN, GZ), [sub("unknown", GZ, IGN)], lines) == {IGN}
    assert wire_types(NAMES, [sub("fortress", "ignition.msgs.Pose")], lines) == set()
    # Mixed lines on one topic: each typed subscriber gets its own.
    assert wire_types(NAMES, [sub("fortress", IGN), sub("harmonic", GZ)], lines) == {GZ, IGN}


def _heartbeat(process: str, with_record: bool) -> bytes:
    pub = record(process) if with_record else None
    return encode_discovery(DiscoveryMessage(DiscoveryType.HEARTBEAT, process, pub=pub))


def test_peer_spelling_from_heartbeats_and_what_a_peer_advertises() -> None:
    engine = DiscoveryEngine("me", 0.0)
    fortress, harmonic = "f" * 36, "h" * 36
    engine.datagram_received(_heartbeat(fortress, with_record=False), "127.0.0.1", 0.0)
    engine.datagram_received(_heartbeat(harmonic, with_record=True), "127.0.0.1", 0.0)
    assert engine.spellings.of(fortress) is Spelling.IGNITION
    assert engine.spellings.of(harmonic) is Spelling.GZ
    # What a process advertises says more than its heartbeats (a Garden process: gz names).
    garden = "g" * 36
    engine.datagram_received(_heartbeat(garden, with_record=False), "127.0.0.1", 0.0)
    advertised = DiscoveryMessage(DiscoveryType.ADVERTISE, garden, pub=record(garden))
    engine.datagram_received(encode_discovery(advertised), "127.0.0.1", 0.0)
    assert engine.spellings.of(garden) is Spelling.GZ
    assert engine.spellings.legacy_processes == {fortress, garden}
    assert engine.spellings.modern == {harmonic}


def test_garden_setting_reads_legacy_heartbeats_as_gz() -> None:
    spellings = PeerSpellings(legacy=Spelling.GZ)
    spellings.saw_heartbeat("p", with_record=False)
    assert spellings.of("p") is Spelling.GZ
    version = spellings.version
    spellings.saw_type("p", "ignition.msgs.Clock")
    assert spellings.of("p") is Spelling.IGNITION
    assert spellings.version == version + 1
    spellings.saw_type("p", "gz.msgs.Clock")  # both spellings: our own kind of peer
    assert spellings.of("p") is Spelling.GZ  # back to the heartbeat's word


def test_cache_recomputes_only_when_the_book_changes() -> None:
    book = SubscriberBook()
    cache = WireTypeCache(book, "@/p@/cmd", NAMES)
    assert cache.get() == frozenset()
    book.set_subscribers("@/p@/cmd", (sub("fortress", IGN),))
    assert cache.get() == {IGN}
    book.set_spellings({"fortress": Spelling.IGNITION})
    book.set_subscribers("@/p@/cmd", (sub("fortress", GZ, IGN),))
    assert cache.get() == {IGN}
    book.set_subscribers("@/p@/cmd", ())
    assert cache.get() == frozenset()


def test_watchers_hear_their_topics_changes_and_every_spelling_change() -> None:
    book = SubscriberBook()
    heard: list[str] = []
    stop_cmd = book.watch("@/p@/cmd", lambda: heard.append("cmd"))
    book.watch("@/p@/odom", lambda: heard.append("odom"))
    book.set_subscribers("@/p@/cmd", (sub("fortress", IGN),))
    book.set_subscribers("@/p@/scan", (sub("fortress", IGN),))  # nobody watches it
    assert heard == ["cmd"]
    book.set_spellings({"fortress": Spelling.IGNITION})
    assert sorted(heard) == ["cmd", "cmd", "odom"]
    stop_cmd()
    stop_cmd()  # twice is harmless
    heard.clear()
    book.set_subscribers("@/p@/cmd", ())
    book.set_spellings({})
    assert heard == ["odom"]

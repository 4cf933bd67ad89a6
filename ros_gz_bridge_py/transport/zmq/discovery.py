"""The UDP discovery protocol as a sans-IO state machine (docs/protocol-zmq-discovery.md §2.3-§2.7).

One :class:`DiscoveryEngine` serves one discovery port (a node runs one for topics on the
msg port and one for services on the srv port, §2.1). It owns no socket and no clock: the
runner feeds it datagrams and the time, and sends what it returns (:mod:`~.discovery_events`).
Bad datagrams are counted in :attr:`DiscoveryEngine.counts` and never raise.
"""

from __future__ import annotations

import collections
import logging
import math
from collections.abc import Iterable, Iterator
from dataclasses import replace

from ros_gz_bridge_py.errors import RemoteProtocolError
from ros_gz_bridge_py.msgs.names import GENERIC_TYPE, Spelling, spelling_of
from ros_gz_bridge_py.transport.api import Scope
from ros_gz_bridge_py.transport.wire_types import PeerSpellings, RemoteSubscriber
from ros_gz_bridge_py.transport.zmq.discovery_events import (
    Event,
    Outgoing,
    PublisherAdded,
    PublisherRemoved,
    Result,
    SubscriberAdded,
    SubscriberRemoved,
)
from ros_gz_bridge_py.transport.zmq.discovery_memo import DatagramMemo
from ros_gz_bridge_py.transport.zmq.discovery_tables import drop_process
from ros_gz_bridge_py.transport.zmq.wire import (
    WIRE_VERSION,
    DiscoveryMessage,
    DiscoveryType,
    MessagePublisher,
    PublisherRecord,
    UnknownMessageTypeError,
    encode_discovery,
    is_tcp_endpoint,
)

_LOG = logging.getLogger("ros_gz_bridge_py.transport")

# Timers in seconds, §2.5 (gz-transport Discovery.hh constants).
#: Send HEARTBEAT and re-ADVERTISE every local record this often.
HEARTBEAT_INTERVAL = 1.0
#: gz-transport checks peers for silence this often; a silent peer is forgotten within this
#: long after SILENCE_INTERVAL. We check when the first one can have gone silent, no sooner.
ACTIVITY_INTERVAL = 0.1
#: Forget a peer process not heard from for longer than this.
SILENCE_INTERVAL = 3.0
#: Discovery counts as initialised (listings are complete) after two heartbeat cycles.
INIT_DELAY = 2 * HEARTBEAT_INTERVAL


def _silent_after(seen: float) -> float:
    """When a peer last heard from at ``seen`` is checked for silence."""
    return seen + SILENCE_INTERVAL + ACTIVITY_INTERVAL


class DiscoveryEngine:
    """Discovery state of one process on one port."""

    def __init__(
        self,
        process_uuid: str,
        now: float,
        *,
        local_ips: Iterable[str] = (),
        relays: Iterable[str] = (),
        version: int = WIRE_VERSION,
        legacy_spelling: Spelling = Spelling.IGNITION,
        respelled_nodes: Iterable[str] = (),
    ) -> None:
        self.process_uuid = process_uuid
        self.version = version
        self.started = now
        self.counts: collections.Counter[str] = collections.Counter()
        self._local_ips = frozenset(local_ips)
        self._relays: list[str] = list(dict.fromkeys(relays))
        self._local: list[PublisherRecord] = []
        self._local_subscribers: list[PublisherRecord] = []
        # topic -> process uuid -> records
        self._remote: dict[str, dict[str, list[PublisherRecord]]] = {}
        self._activity: dict[str, float] = {}
        # topic -> {(process, node): the type names it registered for}
        self._subscribers: dict[str, dict[tuple[str, str], frozenset[str]]] = {}
        # topic -> process -> (source IP) of its SUBSCRIBE, for explanations
        self._subscribe_seen: dict[str, dict[str, str]] = {}
        # topic -> (process, node) -> the record of a SUBSCRIBERS_REP (gz-transport 13+)
        self._listed: dict[str, dict[tuple[str, str], PublisherRecord]] = {}
        #: What each peer process calls its message types (docs/protocol-lines.md §9).
        self.spellings = PeerSpellings(legacy_spelling)
        self._next_heartbeat = now
        self._next_activity = math.inf  # no peer yet
        self.memo = DatagramMemo()
        #: The node ids of the records that announce our publishers under their second
        #: spelling (docs/protocol-lines.md §9.2), repeated only while a peer may use it.
        self._respelled_nodes = frozenset(respelled_nodes)

    # --- queries -------------------------------------------------------------------------

    def remote_publishers(self, topic: str) -> list[PublisherRecord]:
        """Known remote records for the FQN ``topic``."""
        return [r for records in self._remote.get(topic, {}).values() for r in records]

    def all_publishers(self) -> Iterator[PublisherRecord]:
        """Every known record, local ones first."""
        yield from self._local
        for by_process in self._remote.values():
            for records in by_process.values():
                yield from records

    def remote_subscribers(self, topic: str) -> tuple[RemoteSubscriber, ...]:
        """The remote nodes registered (NEW_CONNECTION) for our FQN ``topic``."""
        return tuple(
            RemoteSubscriber(process, node, types)
            for (process, node), types in self._subscribers.get(topic, {}).items()
        )

    def registered_topics(self) -> list[str]:
        """Our FQNs that remote nodes registered with (NEW_CONNECTION)."""
        return list(self._subscribers)

    def subscribe_sightings(self) -> dict[str, dict[str, str]]:
        """FQN -> process -> source IP, for every SUBSCRIBE heard (any partition)."""
        return {topic: dict(seen) for topic, seen in self._subscribe_seen.items()}

    def listed_subscribers(self) -> list[PublisherRecord]:
        """The subscriptions peers listed in SUBSCRIBERS_REP (gz-transport 13+, any partition)."""
        return [record for by_node in self._listed.values() for record in by_node.values()]

    def subscribers_request(self) -> list[Outgoing]:
        """SUBSCRIBERS_REQ: ask gz-transport 13+ peers to list their subscriptions (11 and 12
        print an error for it, so send it only when every peer is newer)."""
        return self._send(DiscoveryType.SUBSCRIBERS_REQ)

    def processes(self) -> list[str]:
        """Every peer process heard from and not yet expired."""
        return list(self._activity)

    def next_deadline(self) -> float:
        """When :meth:`tick` next has something to do."""
        return min(self._next_heartbeat, self._next_activity)

    # --- local actions -------------------------------------------------------------------

    def advertise(self, record: PublisherRecord) -> list[Outgoing]:
        """Own ``record`` and announce it (PROCESS scope stays local)."""
        self._local.append(record)
        if record.scope == Scope.PROCESS:
            return []
        return self._send(DiscoveryType.ADVERTISE, pub=record)

    def unadvertise(self, record: PublisherRecord) -> list[Outgoing]:
        """Forget ``record``, announce that, and drop its remote subscribers."""
        if record not in self._local:
            return []
        self._local.remove(record)
        self.memo.forget(record)
        if not any(r.topic == record.topic for r in self._local):
            self._subscribers.pop(record.topic, None)
        if record.scope == Scope.PROCESS:
            return []
        return self._send(DiscoveryType.UNADVERTISE, pub=record)

    def subscribe(self, topic: str) -> list[Outgoing]:
        """Ask publishers of the FQN ``topic`` to advertise now (SUBSCRIBE)."""
        return self._send(DiscoveryType.SUBSCRIBE, topic=topic)

    def add_local_subscriber(self, record: PublisherRecord) -> None:
        """Remember a local subscription, for SUBSCRIBERS_REP answers."""
        self._local_subscribers.append(record)

    def remove_local_subscriber(self, record: PublisherRecord) -> None:
        """Forget a local subscription registered with :meth:`add_local_subscriber`."""
        if record in self._local_subscribers:
            self._local_subscribers.remove(record)

    def connect(self, publisher: PublisherRecord, node_uuid: str) -> list[Outgoing]:
        """NEW_CONNECTION: our ``node_uuid`` subscribes to ``publisher`` (docs/protocol-zmq-data.md
        §2.8.1 step 5)."""
        record = replace(
            publisher,
            process_uuid=self.process_uuid,
            node_uuid=node_uuid,
            msg=replace(publisher.msg or MessagePublisher(""), ctrl=publisher.process_uuid),
        )
        return self._send(DiscoveryType.NEW_CONNECTION, pub=record)

    def disconnect(
        self, topic: str, node_uuid: str, address: str, publisher_processes: Iterable[str]
    ) -> list[Outgoing]:
        """END_CONNECTION per publisher process and once with an empty ctrl (§2.4)."""
        out: list[Outgoing] = []
        for ctrl in [*dict.fromkeys(publisher_processes), ""]:
            record = PublisherRecord(
                topic, address, self.process_uuid, node_uuid, Scope.ALL,
                MessagePublisher(GENERIC_TYPE, ctrl=ctrl),
            )  # fmt: skip
            out += self._send(DiscoveryType.END_CONNECTION, pub=record)
        return out

    def bye(self) -> list[Outgoing]:
        """UNADVERTISE every local record, then BYE; the engine is done afterwards."""
        out: list[Outgoing] = []
        for record in list(self._local):
            out += self.unadvertise(record)
        return out + self._send(DiscoveryType.BYE)

    # --- input ---------------------------------------------------------------------------

    def tick(self, now: float) -> Result:
        """Heartbeats, re-advertisements and expiry of silent peers that are due at ``now``."""
        out: list[Outgoing] = []
        events: list[Event] = []
        if now >= self._next_heartbeat:
            out += self._send(DiscoveryType.HEARTBEAT)
            spoken = {self.spellings.of(process) for process in self._activity}
            for record in self._local:
                if record.scope != Scope.PROCESS and self._repeats(record, spoken):
                    out += self._send(DiscoveryType.ADVERTISE, pub=record)
            self._next_heartbeat = max(self._next_heartbeat + HEARTBEAT_INTERVAL, now)
        if now >= self._next_activity:
            for process, seen in list(self._activity.items()):
                if now - seen > SILENCE_INTERVAL:
                    self.counts["peers_expired"] += 1
                    _LOG.debug("discovery: peer %s silent for %.1f s", process, now - seen)
                    events += self._forget_process(process)
            self._next_activity = self._first_silence()
        return out, events

    def _repeats(self, record: PublisherRecord, spoken: set[Spelling | None]) -> bool:
        """Whether ``record`` is advertised again this second. The announcement of one of our
        publishers under its second spelling is, only while a live peer uses that spelling or
        has not shown its own yet (None in ``spoken``): it was sent when the publisher was made
        and answers every SUBSCRIBE, and in a simulation of one line nobody reads it."""
        if record.node_uuid not in self._respelled_nodes:
            return True
        return None in spoken or spelling_of(record.msg_type) in spoken

    def _first_silence(self) -> float:
        """When the peer heard from longest ago will have been silent too long (an idle I/O
        thread then wakes for heartbeats only, not ten times a second)."""
        return _silent_after(min(self._activity.values(), default=math.inf))

    def datagram_received(self, data: bytes, source_ip: str, now: float) -> Result:
        """Handle one datagram from ``source_ip``; never raises on bad input."""
        self.counts["received"] += 1
        try:
            message = self.memo.decode(data)
        except UnknownMessageTypeError as error:
            self.counts["unknown_type"] += 1
            _LOG.debug("discovery: dropped datagram from %s: %s", source_ip, error)
            return [], []
        except RemoteProtocolError as error:
            self.counts["malformed"] += 1
            _LOG.debug("discovery: dropped datagram from %s: %s", source_ip, error)
            return [], []
        if message.version != self.version:
            self.counts["wrong_version"] += 1
            _LOG.debug("discovery: dropped version %d from %s", message.version, source_ip)
            return [], []
        if message.process_uuid == self.process_uuid:
            return [], []
        if message.relay:
            # §2.7: re-multicast for the local processes, and relay back to the sender.
            self.add_relay(source_ip)
            again = replace(message, relay=False, no_relay=True)
            return [Outgoing(encode_discovery(again))], []
        out: list[Outgoing] = []
        if not message.no_relay and self._relays:
            relayed = encode_discovery(replace(message, relay=True))
            out += [Outgoing(relayed, ip) for ip in self._relays]
        self._activity[message.process_uuid] = now
        self._next_activity = min(self._next_activity, _silent_after(now))
        try:
            more, events = self._dispatch(message, source_ip, now)
        except RemoteProtocolError as error:
            self.counts["malformed"] += 1
            _LOG.debug("discovery: dropped %s from %s: %s", message.type.name, source_ip, error)
            return out, []
        return out + more, events

    def add_relay(self, ip: str) -> None:
        """Also send every message by unicast to ``ip`` (GZ_RELAY, §2.7)."""
        if ip not in self._relays:
            self._relays.append(ip)

    # --- internals -----------------------------------------------------------------------

    def _send(
        self,
        kind: DiscoveryType,
        *,
        pub: PublisherRecord | None = None,
        topic: str | None = None,
    ) -> list[Outgoing]:
        message = DiscoveryMessage(kind, self.process_uuid, self.version, topic=topic, pub=pub)
        out = [Outgoing(self.memo.encode(message))]
        if self._relays:
            relayed = encode_discovery(replace(message, relay=True))
            out += [Outgoing(relayed, ip) for ip in self._relays]
        return out

    def _in_scope(self, record: PublisherRecord, source_ip: str) -> bool:
        if record.scope == Scope.PROCESS:
            return False
        if record.scope == Scope.HOST:
            return source_ip in self._local_ips or source_ip.startswith("127.")
        return True

    def _dispatch(self, message: DiscoveryMessage, source_ip: str, now: float) -> Result:
        kind = message.type
        if kind == DiscoveryType.HEARTBEAT:
            # gz-transport 13+ fill a publisher record in heartbeats; 11 and 12 do not.
            self.spellings.saw_heartbeat(message.process_uuid, message.pub is not None)
            return [], []
        if kind == DiscoveryType.SUBSCRIBERS_REP:
            pub = message.pub
            if pub is not None and pub.topic:
                key = (pub.process_uuid, pub.node_uuid)
                self._listed.setdefault(pub.topic, {})[key] = pub
                self.spellings.saw_type(pub.process_uuid, pub.msg_type)
            return [], []
        if kind == DiscoveryType.BYE:
            return [], self._forget_process(message.process_uuid)
        if kind == DiscoveryType.SUBSCRIBE:
            if message.topic is None:
                msg = "SUBSCRIBE without a topic"
                raise RemoteProtocolError(msg)
            seen = self._subscribe_seen.setdefault(message.topic, {})
            seen[message.process_uuid] = source_ip
            return self._answer_subscribe(message.topic, source_ip), []
        if kind == DiscoveryType.SUBSCRIBERS_REQ:
            out: list[Outgoing] = []
            for record in self._local_subscribers:
                out += self._send(DiscoveryType.SUBSCRIBERS_REP, pub=record)
            return out, []
        pub = message.pub
        if pub is None:
            msg = f"{kind.name} without a publisher record"
            raise RemoteProtocolError(msg)
        if kind in (DiscoveryType.ADVERTISE, DiscoveryType.UNADVERTISE):
            if not self._in_scope(pub, source_ip):
                return [], []
            if kind == DiscoveryType.ADVERTISE and not is_tcp_endpoint(pub.address):
                self.counts["addresses_refused"] += 1
                _LOG.debug("discovery: refused address %r from %s", pub.address, source_ip)
                return [], []
            if kind == DiscoveryType.ADVERTISE:
                if pub.msg is not None:
                    self.spellings.saw_type(pub.process_uuid, pub.msg_type)
                return [], self._on_advertise(pub)
            return [], self._on_unadvertise(pub)
        if kind == DiscoveryType.NEW_CONNECTION:
            return [], self._on_new_connection(pub)
        if kind == DiscoveryType.END_CONNECTION:
            return [], self._on_end_connection(pub)
        msg = f"unexpected message type {kind.name}"
        raise RemoteProtocolError(msg)

    def _answer_subscribe(self, topic: str, source_ip: str) -> list[Outgoing]:
        out: list[Outgoing] = []
        for record in self._local:
            if record.topic == topic and self._in_scope(record, source_ip):
                out += self._send(DiscoveryType.ADVERTISE, pub=record)
        return out

    def _on_advertise(self, record: PublisherRecord) -> list[Event]:
        records = self._remote.setdefault(record.topic, {}).setdefault(record.process_uuid, [])
        events: list[Event] = []
        for known in list(records):
            if known.node_uuid != record.node_uuid:
                continue
            if known.address == record.address:
                return []
            # The same node now advertises from another address: it moved.
            records.remove(known)
            events.append(PublisherRemoved(known))
        records.append(record)
        events.append(PublisherAdded(record))
        return events

    def _on_unadvertise(self, record: PublisherRecord) -> list[Event]:
        by_process = self._remote.get(record.topic, {})
        records = by_process.get(record.process_uuid, [])
        gone = [r for r in records if r.node_uuid == record.node_uuid]
        for known in gone:
            records.remove(known)
        if not records:
            by_process.pop(record.process_uuid, None)
        if not by_process:
            self._remote.pop(record.topic, None)
        return [PublisherRemoved(r) for r in gone]

    def _forget_process(self, process: str) -> list[Event]:
        self._activity.pop(process, None)
        self.spellings.forget(process)
        for topic in list(self._subscribe_seen):
            self._forget_sighting(topic, process)
        drop_process(self._listed, process)
        events: list[Event] = []
        for topic in list(self._remote):
            records = self._remote[topic].pop(process, [])
            events += [PublisherRemoved(r) for r in records]
            if not self._remote[topic]:
                del self._remote[topic]
        # Its subscriptions to our topics go with it, as gz-transport drops a gone process's
        # remote subscribers (one killed, without END_CONNECTION, was kept for good).
        gone = drop_process(self._subscribers, process)
        return events + [SubscriberRemoved(topic, *key) for topic, key in gone]

    def _on_new_connection(self, record: PublisherRecord) -> list[Event]:
        if record.msg is None:
            msg = "NEW_CONNECTION without a message publisher"
            raise RemoteProtocolError(msg)
        if record.msg.ctrl != self.process_uuid:
            return []
        key = (record.process_uuid, record.node_uuid)
        subscribers = self._subscribers.setdefault(record.topic, {})
        known = subscribers.get(key, frozenset())
        if record.msg.msg_type in known:
            return []
        subscribers[key] = known | {record.msg.msg_type}
        return [SubscriberAdded(record.topic, *key, record.msg.msg_type)]

    def _forget_sighting(self, topic: str, process: str) -> None:
        seen = self._subscribe_seen.get(topic, {})
        seen.pop(process, None)
        if not seen:
            self._subscribe_seen.pop(topic, None)

    def _on_end_connection(self, record: PublisherRecord) -> list[Event]:
        ctrl = record.msg.ctrl if record.msg is not None else ""
        if ctrl not in ("", self.process_uuid):
            return []
        subscribers = self._subscribers.get(record.topic, {})
        if subscribers.pop((record.process_uuid, record.node_uuid), None) is None:
            return []
        if not subscribers:
            self._subscribers.pop(record.topic, None)
        if not any(process == record.process_uuid for process, _node in subscribers):
            # Its process no longer subscribes (it left, or is leaving): its SUBSCRIBE is
            # history, not a subscriber that declined our type (core/diagnosis.py).
            self._forget_sighting(record.topic, record.process_uuid)
        return [SubscriberRemoved(record.topic, record.process_uuid, record.node_uuid)]

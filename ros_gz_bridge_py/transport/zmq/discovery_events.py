"""What a discovery engine (:mod:`~.discovery`) hands its runner: the datagrams to send, and
events about remote publishers and subscribers (docs/protocol-zmq-discovery.md §2.4)."""

from __future__ import annotations

from dataclasses import dataclass

from ros_gz_bridge_py.transport.zmq.wire import PublisherRecord


@dataclass(frozen=True, slots=True)
class Outgoing:
    """A datagram to send: to the multicast group (``relay_ip`` None) or to one relay."""

    data: bytes
    relay_ip: str | None = None


@dataclass(frozen=True, slots=True)
class PublisherAdded:
    """A remote publisher record appeared (a new entry, §2.4 ADVERTISE)."""

    record: PublisherRecord


@dataclass(frozen=True, slots=True)
class PublisherRemoved:
    """A remote publisher record went away (UNADVERTISE, BYE, silence, replaced address)."""

    record: PublisherRecord


@dataclass(frozen=True, slots=True)
class SubscriberAdded:
    """A remote node subscribed to one of our topics (NEW_CONNECTION with our ctrl)."""

    topic: str
    process_uuid: str
    node_uuid: str
    msg_type: str


@dataclass(frozen=True, slots=True)
class SubscriberRemoved:
    """A remote node unsubscribed from one of our topics (END_CONNECTION)."""

    topic: str
    process_uuid: str
    node_uuid: str


Event = PublisherAdded | PublisherRemoved | SubscriberAdded | SubscriberRemoved
Result = tuple[list[Outgoing], list[Event]]

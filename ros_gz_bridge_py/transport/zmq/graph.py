"""What the ZeroMQ discovery engines know, as listings and graph endpoints (pure functions).

``gz topic -l``/``-i`` and ``gz service -l``/``-i`` rows (docs/protocol.md §1.1, §5), and the
publishers and subscribers of one topic or of all, in every partition, for explanations and
discovered bridging: publishers from
ADVERTISE, subscribers from SUBSCRIBE (no type: gz-transport 11/12 subscribers tell nothing
else), SUBSCRIBERS_REP (13+, with the type) and NEW_CONNECTION to our own publishers.
"""

from __future__ import annotations

from ros_gz_bridge_py.msgs.names import GENERIC_TYPE
from ros_gz_bridge_py.transport.api import PUBLISHER, SUBSCRIBER, GraphEndpoint, TopicInfo
from ros_gz_bridge_py.transport.names import decompose
from ros_gz_bridge_py.transport.zmq.discovery import DiscoveryEngine


def names(engine: DiscoveryEngine, partition: str, *, services: bool) -> list[str]:
    """Topic (or service) names with a publisher (provider) in ``partition``."""
    found: set[str] = set()
    for record in engine.all_publishers():
        parts = decompose(record.topic)
        if parts is None or (record.srv is not None) != services:
            continue
        record_partition, name = parts
        if record_partition.removeprefix("/") == partition:
            found.add(name)
    return sorted(found)


def infos(engine: DiscoveryEngine, fqn: str) -> list[TopicInfo]:
    """The publishers (or providers) of ``fqn``; services say ``"<req>&<rep>"``."""
    name = (decompose(fqn) or ("", fqn))[1]
    rows = []
    for record in engine.all_publishers():
        if record.topic != fqn:
            continue
        req = rep = ""
        msg_type = record.msg_type
        if record.srv is not None:
            req, rep = record.srv.request_type, record.srv.response_type
            msg_type = f"{req}&{rep}"
        ids = (record.address, record.process_uuid, record.node_uuid)
        rows.append(TopicInfo(name, msg_type, *ids, request_type=req, response_type=rep))
    return rows


def observe(engine: DiscoveryEngine, fqn: str, own_process: str) -> list[GraphEndpoint]:
    """Every other process's publisher and subscriber of ``fqn``'s name, in every partition."""
    return endpoints(engine, own_process, (decompose(fqn) or ("", fqn))[1])


def endpoints(
    engine: DiscoveryEngine, own_process: str, name: str | None = None
) -> list[GraphEndpoint]:
    """Every other process's publisher and subscriber of topic ``name`` (None: of every
    topic), in every partition."""

    def split(other: str) -> tuple[str, str] | None:
        parts = decompose(other)
        if parts is None or (name is not None and parts[1] != name):
            return None
        return parts[0].removeprefix("/"), parts[1]

    found = [
        GraphEndpoint(PUBLISHER, *where, record.msg_type, record.process_uuid, record.address)
        for record in engine.all_publishers()
        if record.msg is not None
        and record.process_uuid != own_process
        and (where := split(record.topic)) is not None
    ]
    # Per (partition, topic, process), the best we know: SUBSCRIBE (no type), then a listing
    # (its type), then a registration with our publisher (the spellings it took).
    subscribers: dict[tuple[str, str, str], GraphEndpoint] = {}
    for topic, seen in engine.subscribe_sightings().items():
        if (where := split(topic)) is not None:
            for process, ip in seen.items():
                subscribers[(*where, process)] = GraphEndpoint(SUBSCRIBER, *where, "", process, ip)
    for record in engine.listed_subscribers():
        if (where := split(record.topic)) is not None:
            subscribers[(*where, record.process_uuid)] = GraphEndpoint(
                SUBSCRIBER, *where, record.msg_type, record.process_uuid, record.address
            )
    for topic in engine.registered_topics():
        if (where := split(topic)) is None:
            continue
        for remote in engine.remote_subscribers(topic):
            msg_type = next(iter(remote.types)) if len(remote.types) == 1 else GENERIC_TYPE
            known = subscribers.get((*where, remote.process_uuid))
            subscribers[(*where, remote.process_uuid)] = GraphEndpoint(
                SUBSCRIBER, *where, msg_type, remote.process_uuid,
                known.location if known else "", registered=True,
            )  # fmt: skip
    return found + [s for s in subscribers.values() if s.process_uuid != own_process]

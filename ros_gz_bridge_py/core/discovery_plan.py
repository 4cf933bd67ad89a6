"""What to bridge from what Gazebo discovery and the ROS graph show: pure functions, no rclpy,
no transport.

From every endpoint of the bridge's partition (``GzNode.graph``) each topic gets a
:class:`Sighting`; :func:`plan` turns the sightings into one
:class:`~ros_gz_bridge_py.config.TopicBridgeSpec` per topic to bridge, in this order:

1. a topic that an explicit entry (arguments, YAML, ``bridges.*``) names is left to it;
2. else the first YAML entry completed by discovery (wildcard, left-out type) that matches it;
3. else, with ``auto_bridge``, the topic itself, if the allow and deny patterns admit it.

The types, by the first rule that applies (each spec's ``discovered_by`` names it):

- *typed Gazebo publisher*: the type the topic's Gazebo publishers announce;
- *typed Gazebo subscriber*: with no publisher, the one its subscribers announce;
- *inferred from the ROS publisher's type* (``auto_bridge`` only): a topic whose only Gazebo
  subscribers tell no type (gz-transport 11/12 with ZeroMQ) takes the type of the ROS
  publishers (not the bridge's) on its ROS name, and that type's default Gazebo type
  (``bridge_types --get-ros-to-gz``), spelled as the subscribers' Gazebo line spells it when
  discovery tells the line (docs/protocol-lines.md §9.2).

A topic whose endpoints disagree, or that no rule types, is skipped with a reason. The ROS type
is the entry's, else the ROS publishers' type where it pairs with the Gazebo type, else the
default ROS type of the Gazebo type (``bridge_types --get-gz-to-ros``); a ROS publisher of a
type that does not pair with a typed Gazebo subscriber's is said in a note (the Gazebo type
wins). Direction: the entry's, else Gazebo -> ROS when Gazebo publishes, ROS -> Gazebo when
Gazebo only subscribes. ``auto_bridge`` names ROS topics by
:func:`~ros_gz_bridge_py.config.names.ros_name_for_gz`, relative, so the node namespace
applies, and lazily.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass, field

from ros_gz_bridge_py.config import BridgeSpec, Direction, TopicBridgeSpec
from ros_gz_bridge_py.config.discovered import AutoBridgeRules
from ros_gz_bridge_py.config.names import ros_name_for_gz
from ros_gz_bridge_py.config.patterns import TopicPattern
from ros_gz_bridge_py.converters.registry import Registry
from ros_gz_bridge_py.msgs.names import (
    GENERIC_TYPE,
    Spelling,
    canonical_type,
    respell,
    same_message,
)
from ros_gz_bridge_py.transport.api import PUBLISHER, GraphEndpoint

#: The ``source`` of bridges made by ``auto_bridge``.
AUTO_SOURCE = "auto_bridge"
#: The rules that type a discovered topic (``TopicBridgeSpec.discovered_by``).
BY_GZ_PUBLISHER = "typed Gazebo publisher"
BY_GZ_SUBSCRIBER = "typed Gazebo subscriber"
BY_ROS_PUBLISHER = "inferred from the ROS publisher's type"
#: Types given by a YAML entry that discovery completed.
BY_ENTRY = "the entry's type"

#: ROS name (as :func:`auto_ros_name` writes it) -> the distinct types of its ROS publishers,
#: the bridge's own left out.
RosPublishers = Mapping[str, tuple[str, ...]]


@dataclass(frozen=True)
class Sighting:
    """One Gazebo topic of the partition as discovery shows it (other processes only)."""

    topic: str
    #: The distinct types its publishers announce, as announced.
    publisher_types: tuple[str, ...] = ()
    #: The distinct types its subscribers announce (generic subscribers left out).
    subscriber_types: tuple[str, ...] = ()
    #: Subscribers that tell no type (gz-transport 11/12) or take any (generic).
    untyped_subscribers: int = 0
    #: How the processes of those subscribers spell types, when discovery tells it for all
    #: of them and they agree.
    untyped_spelling: Spelling | None = None


def sightings(
    endpoints: Iterable[GraphEndpoint],
    partition: str,
    peer_spelling: Callable[[str], Spelling | None] = lambda _: None,
) -> dict[str, Sighting]:
    """The topics of ``partition`` (written without a leading ``/``) by name;
    ``peer_spelling``: a process's spelling, when known (``GzNode.peer_spelling``)."""
    publishers: dict[str, list[str]] = {}
    typed: dict[str, list[str]] = {}
    untyped: dict[str, list[Spelling | None]] = {}
    wanted = partition.strip("/")
    for endpoint in endpoints:
        if endpoint.partition.strip("/") != wanted:
            continue
        if endpoint.role == PUBLISHER:
            publishers.setdefault(endpoint.topic, []).append(endpoint.msg_type)
        elif endpoint.msg_type and endpoint.msg_type != GENERIC_TYPE:
            typed.setdefault(endpoint.topic, []).append(endpoint.msg_type)
        else:
            untyped.setdefault(endpoint.topic, []).append(peer_spelling(endpoint.process_uuid))
    return {
        topic: Sighting(
            topic,
            tuple(dict.fromkeys(publishers.get(topic, ()))),
            tuple(dict.fromkeys(typed.get(topic, ()))),
            len(untyped.get(topic, ())),
            _one_spelling(untyped.get(topic, [])),
        )
        for topic in sorted({*publishers, *typed, *untyped})
    }


def _one_spelling(spellings: list[Spelling | None]) -> Spelling | None:
    distinct = set(spellings)
    return distinct.pop() if len(distinct) == 1 else None


def auto_ros_name(gz_topic: str) -> str:
    """The ROS name ``auto_bridge`` gives ``gz_topic``: relative ("" when it has none)."""
    return ros_name_for_gz(gz_topic).lstrip("/")


def ros_names_to_read(found: Mapping[str, Sighting]) -> list[str]:
    """The ROS names whose publishers :func:`plan` reads: those of the topics Gazebo only
    subscribes to (as :func:`auto_ros_name` writes them)."""
    names = (auto_ros_name(s.topic) for s in found.values() if not s.publisher_types)
    return sorted({name for name in names if name})


@dataclass(frozen=True)
class Plan:
    """What to bridge: a spec per Gazebo topic, and why each other topic is not bridged."""

    specs: dict[str, TopicBridgeSpec] = field(default_factory=dict)
    #: Gazebo topic -> the reason it is skipped (for a log line per topic and reason).
    skipped: dict[str, str] = field(default_factory=dict)
    #: Gazebo topic -> what a bridged topic's ROS side does that its Gazebo side will not take.
    notes: dict[str, str] = field(default_factory=dict)


def same_bridge(a: TopicBridgeSpec, b: BridgeSpec) -> bool:
    """True if ``a`` and ``b`` bridge alike: the rule that chose the types and the spelling
    of the Gazebo type aside (a Fortress subscriber inferred from ROS shows its type once it
    took our publisher, and both spellings are announced anyway, docs/protocol-lines.md §9.2)."""

    def key(spec: TopicBridgeSpec) -> TopicBridgeSpec:
        return dataclasses.replace(spec, gz_type=canonical_type(spec.gz_type), discovered_by="")

    return isinstance(b, TopicBridgeSpec) and key(a) == key(b)


def gazebo_type(sighting: Sighting) -> tuple[str, str, str]:
    """(the topic's Gazebo type, the rule, "") or ("", "", why it has none)."""
    sides = (
        ("publishers", BY_GZ_PUBLISHER, sighting.publisher_types),
        ("subscribers", BY_GZ_SUBSCRIBER, sighting.subscriber_types),
    )
    for role, rule, types in sides:
        if types:
            if len({canonical_type(t) for t in types}) > 1:
                return "", "", f"its Gazebo {role} disagree on the type ({', '.join(types)})"
            return types[0], rule, ""
    why = (
        "its Gazebo subscribers announce no type (gz-transport 11/12 with ZeroMQ tell only the "
        "topic); add an entry with the types to the YAML, or publish on it from Gazebo"
    )
    return "", "", why


def plan(
    found: dict[str, Sighting],
    *,
    patterns: Sequence[TopicPattern],
    rules: AutoBridgeRules,
    registry: Registry,
    explicit: frozenset[str] = frozenset(),
    ros_publishers: RosPublishers | None = None,
) -> Plan:
    """The bridges ``found`` calls for (module docstring); ``explicit``: Gazebo names that
    explicit entries bridge; ``ros_publishers``: the ROS graph on :func:`ros_names_to_read`."""
    result = Plan()
    auto_names: dict[str, str] = {}  # ROS name -> the Gazebo topic auto_bridge gave it
    for topic, sighting in found.items():
        if topic in explicit:
            continue
        matched = _first_match(patterns, topic)
        if matched is None and not (rules.enabled and rules.admits(topic)):
            continue
        if matched is not None:
            spec, why = _from_pattern(matched, sighting, registry)
        else:
            spec, why, note = _auto(sighting, ros_publishers or {}, registry)
            if note:
                result.notes[topic] = note
            if spec is not None and auto_names.setdefault(spec.ros_topic, topic) != topic:
                why = f"its ROS name {spec.ros_topic} is taken by {auto_names[spec.ros_topic]}"
                spec = None
        if spec is None:
            result.skipped[topic] = why
            result.notes.pop(topic, None)
        else:
            result.specs[topic] = spec
    return result


def _first_match(
    patterns: Sequence[TopicPattern], topic: str
) -> tuple[TopicPattern, tuple[str, ...]] | None:
    for pattern in patterns:
        captures = pattern.match(topic)
        if captures is not None:
            return pattern, captures
    return None


def _direction(sighting: Sighting) -> Direction:
    return Direction.GZ_TO_ROS if sighting.publisher_types else Direction.ROS_TO_GZ


def _ros_type(gz_type: str, wanted: str, registry: Registry) -> tuple[str, str]:
    """(the ROS type, "") or ("", why there is none)."""
    if wanted:
        if registry.find(wanted, gz_type) is None:
            return "", f"{wanted} does not pair with its Gazebo type {gz_type}"
        return wanted, ""
    ros_types = registry.ros_types_for(gz_type)
    if not ros_types:
        return "", f"its Gazebo type {gz_type} pairs with no ROS type (bridge_types --print-gz)"
    return ros_types[0], ""


def _auto(
    sighting: Sighting, ros_publishers: RosPublishers, registry: Registry
) -> tuple[TopicBridgeSpec | None, str, str]:
    """(the spec or None, why not, a note on ROS publishers that Gazebo will not take)."""
    ros_name = auto_ros_name(sighting.topic)
    if not ros_name:
        return None, "it has no ROS name", ""
    gz_type, rule, why = gazebo_type(sighting)
    ros_types = () if sighting.publisher_types else ros_publishers.get(ros_name, ())
    note = ""
    if gz_type:
        ros_type, why, note = _ros_type_beside(gz_type, ros_name, ros_types, registry)
    elif sighting.untyped_subscribers:
        gz_type, ros_type, why = _inferred(sighting, ros_name, ros_types, registry)
        rule = BY_ROS_PUBLISHER
    if not gz_type or not ros_type:
        return None, why, ""
    spec = TopicBridgeSpec(
        ros_name, sighting.topic, ros_type, gz_type, _direction(sighting), lazy=True,
        source=AUTO_SOURCE, discovered_by=rule,
    )  # fmt: skip
    return spec, "", note


def _ros_type_beside(
    gz_type: str, ros_name: str, ros_types: tuple[str, ...], registry: Registry
) -> tuple[str, str, str]:
    """(the ROS type for ``gz_type``, why there is none, a note on ``ros_types`` (those of the
    ROS publishers) that do not pair with it): the first of ``ros_types`` that pairs, else the
    default."""
    paired = [t for t in ros_types if registry.find(t, gz_type) is not None]
    ros_type, why = (paired[0], "") if paired else _ros_type(gz_type, "", registry)
    unpaired = [t for t in ros_types if t not in paired]
    if not ros_type or not unpaired:
        return ros_type, why, ""
    note = (
        f"the ROS publishers of {ros_name} use {', '.join(unpaired)}, which does not pair with "
        f"{gz_type}, the type its Gazebo subscribers take: the bridge follows the Gazebo type "
        f"({ros_type} <-> {gz_type}) and those messages do not reach Gazebo; publish "
        f"{ros_type} in ROS, or write an entry with the types (entries win over discovery)"
    )
    return ros_type, why, note


def _inferred(
    sighting: Sighting, ros_name: str, ros_types: tuple[str, ...], registry: Registry
) -> tuple[str, str, str]:
    """(Gazebo type, ROS type, "") from the ROS publishers of ``ros_name``, or ("", "", why)."""
    if not ros_types:
        why = (
            "its Gazebo subscribers announce no type (gz-transport 11/12 with ZeroMQ tell only "
            f"the topic) and no ROS node publishes on {ros_name} to tell it; publish on it in "
            "ROS, add an entry with the types to the YAML, or publish on it from Gazebo"
        )
        return "", "", why
    if len(ros_types) > 1:
        return "", "", f"its ROS publishers disagree on the type ({', '.join(ros_types)})"
    gz_types = registry.gz_types_for(ros_types[0])
    if not gz_types:
        why = f"its ROS publishers' type {ros_types[0]} pairs with no Gazebo type"
        return "", "", f"{why} (bridge_types --print-ros)"
    spelling = sighting.untyped_spelling
    gz_type = respell(gz_types[0], spelling) if spelling else canonical_type(gz_types[0])
    return gz_type, ros_types[0], ""


def _from_pattern(
    matched: tuple[TopicPattern, tuple[str, ...]],
    sighting: Sighting,
    registry: Registry,
) -> tuple[TopicBridgeSpec | None, str]:
    pattern, captures = matched
    where = f" ({pattern.source})" if pattern.source else ""
    gz_type, rule, why = gazebo_type(sighting)
    if pattern.gz_type:
        if gz_type and not same_message(gz_type, pattern.gz_type):
            return None, f"the entry{where} says {pattern.gz_type}, but Gazebo shows {gz_type}"
        gz_type, rule = (gz_type, rule) if gz_type else (pattern.gz_type, BY_ENTRY)
    if not gz_type and pattern.ros_type:
        gz_types = registry.gz_types_for(pattern.ros_type)
        gz_type = gz_types[0] if len({canonical_type(t) for t in gz_types}) == 1 else ""
        rule = BY_ENTRY
    if not gz_type:
        return None, why
    ros_type, why = _ros_type(gz_type, pattern.ros_type, registry)
    if not ros_type:
        return None, why + where
    direction = pattern.direction or _direction(sighting)
    spec = pattern.completed(
        pattern.ros_name(sighting.topic, captures), sighting.topic, (ros_type, gz_type), direction
    )
    return dataclasses.replace(spec, discovered_by=rule), ""

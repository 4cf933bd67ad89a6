"""What to bridge from what Gazebo discovery shows: pure functions, no rclpy, no transport.

From every endpoint of the bridge's partition (``GzNode.graph``) each topic gets a
:class:`Sighting`; :func:`plan` turns the sightings into one
:class:`~ros_gz_bridge_py.config.TopicBridgeSpec` per topic to bridge, in this order:

1. a topic that an explicit entry (arguments, YAML, ``bridges.*``) names is left to it;
2. else the first YAML entry completed by discovery (wildcard, left-out type) that matches it;
3. else, with ``auto_bridge``, the topic itself, if the allow and deny patterns admit it.

The type is the one the topic's Gazebo publishers announce; with no publisher, the one its
subscribers announce; a topic whose only subscribers tell no type (gz-transport 11/12 with
ZeroMQ) or whose endpoints disagree is skipped with a reason. The ROS type is the entry's, else
the default ROS type of the Gazebo type (``bridge_types --get-gz-to-ros``). Direction: the
entry's, else Gazebo -> ROS when Gazebo publishes, ROS -> Gazebo when Gazebo only subscribes.
``auto_bridge`` names ROS topics by :func:`~ros_gz_bridge_py.config.names.ros_name_for_gz`,
relative, so the node namespace applies, and lazily.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field

from ros_gz_bridge_py.config import Direction, TopicBridgeSpec
from ros_gz_bridge_py.config.discovered import AutoBridgeRules
from ros_gz_bridge_py.config.names import ros_name_for_gz
from ros_gz_bridge_py.config.patterns import TopicPattern
from ros_gz_bridge_py.converters.registry import Registry
from ros_gz_bridge_py.msgs.names import GENERIC_TYPE, canonical_type, same_message
from ros_gz_bridge_py.transport.api import PUBLISHER, GraphEndpoint

#: The ``source`` of bridges made by ``auto_bridge``.
AUTO_SOURCE = "auto_bridge"


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


def sightings(endpoints: Iterable[GraphEndpoint], partition: str) -> dict[str, Sighting]:
    """The topics of ``partition`` (written without a leading ``/``) by name."""
    publishers: dict[str, list[str]] = {}
    typed: dict[str, list[str]] = {}
    untyped: dict[str, int] = {}
    wanted = partition.strip("/")
    for endpoint in endpoints:
        if endpoint.partition.strip("/") != wanted:
            continue
        if endpoint.role == PUBLISHER:
            publishers.setdefault(endpoint.topic, []).append(endpoint.msg_type)
        elif endpoint.msg_type and endpoint.msg_type != GENERIC_TYPE:
            typed.setdefault(endpoint.topic, []).append(endpoint.msg_type)
        else:
            untyped[endpoint.topic] = untyped.get(endpoint.topic, 0) + 1
    return {
        topic: Sighting(
            topic,
            tuple(dict.fromkeys(publishers.get(topic, ()))),
            tuple(dict.fromkeys(typed.get(topic, ()))),
            untyped.get(topic, 0),
        )
        for topic in sorted({*publishers, *typed, *untyped})
    }


@dataclass(frozen=True)
class Plan:
    """What to bridge: a spec per Gazebo topic, and why each other topic is not bridged."""

    specs: dict[str, TopicBridgeSpec] = field(default_factory=dict)
    #: Gazebo topic -> the reason it is skipped (for a log line per topic and reason).
    skipped: dict[str, str] = field(default_factory=dict)


def gazebo_type(sighting: Sighting) -> tuple[str, str]:
    """(the topic's Gazebo type, "") or ("", why it has none)."""
    for role, types in (("publishers", sighting.publisher_types),
                        ("subscribers", sighting.subscriber_types)):  # fmt: skip
        if types:
            if len({canonical_type(t) for t in types}) > 1:
                return "", f"its Gazebo {role} disagree on the type ({', '.join(types)})"
            return types[0], ""
    return "", (
        "its Gazebo subscribers announce no type (gz-transport 11/12 with ZeroMQ tell only the "
        "topic); add an entry with the types to the YAML, or publish on it from Gazebo"
    )


def plan(
    found: dict[str, Sighting],
    *,
    patterns: Sequence[TopicPattern],
    rules: AutoBridgeRules,
    registry: Registry,
    explicit: frozenset[str] = frozenset(),
) -> Plan:
    """The bridges ``found`` calls for (module docstring); ``explicit``: Gazebo names that
    explicit entries bridge."""
    result = Plan()
    auto_names: dict[str, str] = {}  # ROS name -> the Gazebo topic auto_bridge gave it
    for topic, sighting in found.items():
        if topic in explicit:
            continue
        matched = _first_match(patterns, topic)
        if matched is None and not (rules.enabled and rules.admits(topic)):
            continue
        gz_type, why = gazebo_type(sighting)
        if matched is not None:
            spec, why = _from_pattern(matched, sighting, gz_type, why, registry)
        else:
            spec, why = _auto(sighting, gz_type, why, registry)
            if spec is not None and auto_names.setdefault(spec.ros_topic, topic) != topic:
                why = f"its ROS name {spec.ros_topic} is taken by {auto_names[spec.ros_topic]}"
                spec = None
        if spec is None:
            result.skipped[topic] = why
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
    sighting: Sighting, gz_type: str, why: str, registry: Registry
) -> tuple[TopicBridgeSpec | None, str]:
    if not gz_type:
        return None, why
    ros_type, why = _ros_type(gz_type, "", registry)
    ros_name = ros_name_for_gz(sighting.topic).lstrip("/")
    if not ros_type or not ros_name:
        return None, why or "it has no ROS name"
    spec = TopicBridgeSpec(
        ros_name, sighting.topic, ros_type, gz_type, _direction(sighting), lazy=True,
        source=AUTO_SOURCE,
    )  # fmt: skip
    return spec, ""


def _from_pattern(
    matched: tuple[TopicPattern, tuple[str, ...]],
    sighting: Sighting,
    gz_type: str,
    why: str,
    registry: Registry,
) -> tuple[TopicBridgeSpec | None, str]:
    pattern, captures = matched
    where = f" ({pattern.source})" if pattern.source else ""
    if pattern.gz_type:
        if gz_type and not same_message(gz_type, pattern.gz_type):
            return None, f"the entry{where} says {pattern.gz_type}, but Gazebo shows {gz_type}"
        gz_type = gz_type or pattern.gz_type
    if not gz_type and pattern.ros_type:
        gz_types = registry.gz_types_for(pattern.ros_type)
        gz_type = gz_types[0] if len({canonical_type(t) for t in gz_types}) == 1 else ""
    if not gz_type:
        return None, why
    ros_type, why = _ros_type(gz_type, pattern.ros_type, registry)
    if not ros_type:
        return None, why + where
    direction = pattern.direction or _direction(sighting)
    spec = pattern.completed(
        pattern.ros_name(sighting.topic, captures), sighting.topic, (ros_type, gz_type), direction
    )
    return spec, ""

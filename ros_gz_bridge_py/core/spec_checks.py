"""What :meth:`Bridge.add` checks before it builds anything.

The parsers check the entries they read from text; a spec made in Python reaches the bridge
without them, so its fields are checked here by the same rules (``config/model.py``). And an
entry that would bridge what another already bridges is refused: the C++ bridge builds both,
and every message then arrives twice (a service answers every call twice).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Iterable
from typing import Any, TypeVar

from ros_gz_bridge_py.config import (
    BridgeSpec,
    Direction,
    ServiceBridgeSpec,
    TopicBridgeSpec,
)
from ros_gz_bridge_py.config.model import DEPRECATED_DIRECTIONS, as_bool, as_queue, as_rate
from ros_gz_bridge_py.config.names import ROS_NAME_RULE
from ros_gz_bridge_py.errors import ConfigError
from ros_gz_bridge_py.msgs.names import canonical_type
from ros_gz_bridge_py.transport.names import is_valid_topic

#: What one bridge carries: a direction (or "service") and the names and types it joins.
Key = tuple[str, ...]
_T = TypeVar("_T")

_TOPIC_TEXTS = ("ros_topic", "gz_topic", "ros_type", "gz_type")
_EXAMPLES = {
    "ros_topic": "'/chatter'",
    "gz_topic": "'/chatter'",
    "ros_type": "'std_msgs/msg/String'",
    "gz_type": "'gz.msgs.StringMsg'",
    "service": "'/world/default/control'",
    "gz_req_type": "'gz.msgs.WorldControl'",
    "gz_rep_type": "'gz.msgs.Boolean'",
    "frame_id": "'camera_link'",
    "qos_profile": "'SENSOR_DATA'",
}


def checked_spec(spec: object, warn: Callable[[str], None]) -> BridgeSpec:
    """``spec`` as the bridge takes it, its values in their types (``"GZ_TO_ROS"`` becomes
    :class:`Direction`, ``"10"`` a depth of 10); a deprecated spelling (``"IGN_TO_ROS"``) is
    taken and ``warn`` told.

    Raises:
        ConfigError: not a spec, or a field the YAML parser would refuse; the message names
            the entry and the field.
    """
    if isinstance(spec, ServiceBridgeSpec):
        for name in ("service", "ros_type"):
            _text(spec, name, getattr(spec, name))
        for name in ("gz_req_type", "gz_rep_type"):
            if getattr(spec, name) is not None:
                _text(spec, name, getattr(spec, name))
        if (spec.gz_req_type is None) != (spec.gz_rep_type is None):
            msg = "set both gz_req_type and gz_rep_type, or neither"
            raise ConfigError(msg, _where(spec))
        return spec
    if not isinstance(spec, TopicBridgeSpec):
        msg = (
            f"Bridge.add takes a TopicBridgeSpec or a ServiceBridgeSpec, not "
            f"{type(spec).__name__}; parse_cli_args and parse_yaml make them from text"
        )
        raise ConfigError(msg)
    for name in _TOPIC_TEXTS:
        _text(spec, name, getattr(spec, name))
    if spec.frame_id is not None:
        _text(spec, "frame_id", spec.frame_id)
    if spec.qos_profile is not None:
        _text(spec, "qos_profile", spec.qos_profile)  # its name is checked with the QoS
    return dataclasses.replace(
        spec,
        direction=_direction(spec, warn),
        lazy=_optional(spec, "lazy", as_bool),
        publisher_queue=_optional(spec, "publisher_queue", as_queue),
        subscriber_queue=_optional(spec, "subscriber_queue", as_queue),
        max_rate=_optional(spec, "max_rate", as_rate),
    )


def topic_keys(spec: TopicBridgeSpec, ros_topic: str, gz_topic: str) -> list[Key]:
    """One key per channel ``spec`` makes; ``ros_topic`` and ``gz_topic`` as resolved."""
    directions = (
        [Direction.GZ_TO_ROS, Direction.ROS_TO_GZ]
        if spec.direction is Direction.BIDIRECTIONAL
        else [spec.direction]
    )
    types = (spec.ros_type, canonical_type(spec.gz_type))
    return [(direction.value, ros_topic, gz_topic, *types) for direction in directions]


def service_key(service: str) -> Key:
    """The key of a service bridge: its resolved ROS name (a second server there would answer
    every call again, whatever its types)."""
    return ("service", service)


def refuse_twice(spec: BridgeSpec, keys: Iterable[Key], taken: dict[Key, BridgeSpec]) -> None:
    """Raise when one of ``keys`` is ``taken`` already.

    Raises:
        ConfigError: naming the entry, the earlier one and what they share.
    """
    for key in keys:
        earlier = taken.get(key)
        if earlier is None:
            continue
        what = (
            f"the ROS service {key[1]}"
            if isinstance(spec, ServiceBridgeSpec)
            else f"ROS {key[1]} ({spec.ros_type}) and Gazebo {spec.gz_topic} ({spec.gz_type}) "
            f"{key[0]}"
        )
        where = earlier.source or "an earlier Bridge.add"
        msg = (
            f"{what} is bridged already by {where}; a second bridge would pass every "
            f"{'call' if key[0] == 'service' else 'message'} twice. Remove one of the two "
            "entries (Bridge.remove the earlier handle first to replace it)"
        )
        raise ConfigError(msg, _where(spec))


def _where(spec: BridgeSpec) -> str:
    if spec.source:
        return spec.source
    if isinstance(spec, ServiceBridgeSpec):
        return f"service bridge {spec.service!r}"
    return f"topic bridge {spec.ros_topic!r}"


def _text(spec: BridgeSpec, name: str, value: object) -> None:
    if isinstance(value, str) and value:
        return
    given = (
        f"the class {value.__module__}.{value.__qualname__}"
        if isinstance(value, type)
        else repr(value)
    )
    msg = f"{name} must be a non-empty string such as {_EXAMPLES.get(name, repr('x'))}, not {given}"
    raise ConfigError(msg, _where(spec))


def _direction(spec: TopicBridgeSpec, warn: Callable[[str], None]) -> Direction:
    value: Any = spec.direction
    if isinstance(value, Direction):
        return value
    if isinstance(value, str) and value in DEPRECATED_DIRECTIONS:
        replacement = DEPRECATED_DIRECTIONS[value]
        warn(
            f"{spec.source or spec.ros_topic}: direction {value} is deprecated, "
            f"use {replacement.value}"
        )
        return replacement
    try:
        return Direction(value)
    except ValueError:
        names = ", ".join(direction.value for direction in Direction)
        msg = f"direction {value!r} is none of {names}"
        raise ConfigError(msg, _where(spec)) from None


def _optional(spec: TopicBridgeSpec, name: str, convert: Callable[[str, object], _T]) -> _T | None:
    value = getattr(spec, name)
    if value is None:
        return None
    try:
        return convert(name, value)
    except ConfigError as err:
        raise ConfigError(err.message, _where(spec)) from None


def refused_name_fix(spec: TopicBridgeSpec, why: str, program: str = "") -> str:
    """What to write when ``why`` says a side refuses a name of ``spec`` (rcl's words for a
    ROS name, the transport's for a Gazebo one); '' for other failures. ``program``: the
    executable whose arguments name the topics (``image_bridge``), else entries do."""
    if why.startswith("failed to resolve name"):
        fix = f"; [{spec.ros_topic}] is no valid ROS name: {ROS_NAME_RULE}"
        if spec.ros_topic == spec.gz_topic and is_valid_topic(spec.gz_topic):
            rename = (
                f"give it one: {program} {spec.gz_topic}:=<ROS name>"
                if program
                else "set ros_topic_name to a ROS name and gz_topic_name to this one"
            )
            fix += f", though Gazebo takes it: {rename}"
        return fix
    if why.startswith("invalid Gazebo Transport topic") and spec.gz_topic.startswith("~"):
        return "; -p expand_gz_topic_names:=true expands '~' in YAML entries as in ROS names"
    return ""

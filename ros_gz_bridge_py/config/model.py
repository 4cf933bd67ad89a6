"""The values every bridge configuration source parses into, and their shared value rules.

The command line, YAML files and ``bridges.<name>.*`` parameters all produce the same frozen
:class:`TopicBridgeSpec` / :class:`ServiceBridgeSpec` values, collected in a
:class:`ParseResult`. Nothing here touches rclpy or logging: callers decide what to log.
"""

from __future__ import annotations

import enum
import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

from ros_gz_bridge_py.errors import ConfigError

if TYPE_CHECKING:
    from ros_gz_bridge_py.config.patterns import TopicPattern


class Direction(enum.Enum):
    """Which way a topic bridge carries messages. Values are the YAML spellings."""

    BIDIRECTIONAL = "BIDIRECTIONAL"
    GZ_TO_ROS = "GZ_TO_ROS"
    ROS_TO_GZ = "ROS_TO_GZ"


#: Humble-era direction names (``ign`` for Gazebo), accepted with a deprecation warning.
DEPRECATED_DIRECTIONS: dict[str, Direction] = {
    "IGN_TO_ROS": Direction.GZ_TO_ROS,
    "ROS_TO_IGN": Direction.ROS_TO_GZ,
}

#: ``qos_profile`` values, spelled as the C++ bridge spells them (rclcpp's predefined profiles).
QOS_PROFILE_NAMES: frozenset[str] = frozenset(
    {
        "CLOCK",
        "SENSOR_DATA",
        "PARAMETERS",
        "SERVICES",
        "PARAMETER_EVENTS",
        "ROSOUT",
        "SYSTEM_DEFAULT",
        "BEST_AVAILABLE",
    }
)


@dataclass(frozen=True)
class TopicBridgeSpec:
    """One topic bridge as configured; type names are kept exactly as written."""

    ros_topic: str
    gz_topic: str
    ros_type: str
    gz_type: str
    direction: Direction = Direction.BIDIRECTIONAL
    #: None: use the node's ``lazy`` parameter.
    lazy: bool | None = None
    #: None: 10, or the depth of ``qos_profile`` when one is set.
    publisher_queue: int | None = None
    subscriber_queue: int | None = None
    #: One of :data:`QOS_PROFILE_NAMES`.
    qos_profile: str | None = None
    frame_id: str | None = None
    #: Messages per second the bridge passes on at most (the rest is dropped before
    #: conversion); None: the node's ``max_rate``; 0: no limit.
    max_rate: float | None = None
    #: Where it came from, e.g. ``"argument 2"`` or ``"bridge.yaml entry 3 (line 12)"``.
    source: str = ""
    #: The rule of discovered bridging that chose its types ("" for a configured entry).
    discovered_by: str = ""


@dataclass(frozen=True)
class ServiceBridgeSpec:
    """A ROS service forwarded to a Gazebo service; None Gazebo types mean the defaults."""

    service: str
    ros_type: str
    gz_req_type: str | None = None
    gz_rep_type: str | None = None
    source: str = ""


BridgeSpec = TopicBridgeSpec | ServiceBridgeSpec


@dataclass(frozen=True)
class ParseResult:
    """What one configuration source produced: the valid specs, and what was wrong with the rest.

    ``errors`` are entries that were skipped; ``warnings`` are entries that were kept (or
    harmlessly ignored) but deserve the user's attention. Each warning starts with its location.
    """

    specs: tuple[BridgeSpec, ...] = ()
    errors: tuple[ConfigError, ...] = ()
    warnings: tuple[str, ...] = ()
    #: Entries that discovery completes (wildcards, left-out types): ``patterns.py``.
    patterns: tuple[TopicPattern, ...] = ()


class UsageError(ConfigError):
    """A ``parameter_bridge`` argument that cannot be parsed (C++ prints usage and exits 255)."""


def ros_type_hint(ros_type: str) -> str | None:
    """A warning for ``pkg/Type`` written without ``/msg/``: it parses but no converter has it."""
    package, slash, name = ros_type.partition("/")
    if slash and package and name and "/" not in name:
        return (
            f"ROS type '{ros_type}' has no '/msg/' and will not be found; "
            f"did you mean {package}/msg/{name}"
        )
    return None


#: Every spelling yaml-cpp's ``as<bool>`` accepts (its strings are YAML 1.1 booleans plus y/n).
_TRUE_WORDS = frozenset({"y", "yes", "true", "on"})
_FALSE_WORDS = frozenset({"n", "no", "false", "off"})


def as_bool(key: str, value: object) -> bool:
    """``value`` as a bool; strings are accepted the way yaml-cpp accepts them."""
    if isinstance(value, bool):
        return value
    if isinstance(value, str) and value.lower() in _TRUE_WORDS | _FALSE_WORDS:
        return value.lower() in _TRUE_WORDS
    msg = f"{key} must be true or false, got {value!r}"
    raise ConfigError(msg)


#: The deepest ``publisher_queue``/``subscriber_queue``. A channel's native queue allocates a
#: slot per message of its ROS depth when it starts, and ``native/pump.c`` refuses more than
#: ``1 << 24`` slots; a deeper ROS history would only reserve memory nobody reads. A deeper
#: ``qos_overrides`` depth (rclpy applies those) keeps its ROS history, and the channel's queue
#: stops at this bound (``core.channel.delivery_capacity``).
MAX_QUEUE_DEPTH = 1 << 24


def _non_negative_int(value: object) -> int | None:
    """``value`` as an integer >= 0 (a string of digits too); None when it is not one."""
    if isinstance(value, int) and not isinstance(value, bool) and value >= 0:
        return value
    if isinstance(value, str) and value.strip().isascii() and value.strip().isdigit():
        return int(value.strip())
    return None


def as_queue(key: str, value: object) -> int:
    """``value`` as a queue depth: an integer from 0 to :data:`MAX_QUEUE_DEPTH`."""
    depth = _non_negative_int(value)
    # A float too: ROS parameters read an integer beyond int64 as a double (1e+20).
    number = value if depth is None else depth
    if (
        isinstance(number, int | float)
        and not isinstance(number, bool)
        and number > MAX_QUEUE_DEPTH
    ):
        msg = f"{key} must be at most {MAX_QUEUE_DEPTH}, got {number}"
        raise ConfigError(msg)
    if depth is None:
        msg = f"{key} must be a non-negative integer, got {value!r}"
        raise ConfigError(msg)
    return depth


def zero_queue_hint(key: str) -> str:
    """The warning for a queue of 0, which C++ accepts too: ROS reads depth 0 as the
    middleware's default, which users who meant "unbounded" do not expect."""
    return (
        f"{key} 0 means the middleware's default history depth (1 message with Fast DDS or "
        f"Cyclone DDS), not an unbounded queue; set {key} to the depth you want, "
        "or leave it out for the default"
    )


def as_rate(key: str, value: object) -> float:
    """``value`` as a rate in Hz: a finite number >= 0 (0: no limit); digit strings too."""
    number: float | None = None
    if isinstance(value, int | float) and not isinstance(value, bool):
        number = float(value)
    elif isinstance(value, str):
        try:
            number = float(value.strip())
        except ValueError:
            number = None
    if number is None or not math.isfinite(number) or number < 0:
        msg = f"{key} must be a number of messages per second >= 0 (0: no limit), got {value!r}"
        raise ConfigError(msg)
    return number

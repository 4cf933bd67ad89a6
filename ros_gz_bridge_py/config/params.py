"""Bridges defined by node parameters: ``bridge_names`` plus ``bridges.<name>.*``.

The C++ node's rules: docs/behaviour.md §3.2.

This is what the launch action's XML ``<topic>``/``<service>`` children turn into. The checks
and error texts are the C++ node's; the parameter values are read through a callback so this
module stays free of rclpy.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

from ros_gz_bridge_py.config.model import (
    QOS_PROFILE_NAMES,
    BridgeSpec,
    Direction,
    ParseResult,
    ServiceBridgeSpec,
    TopicBridgeSpec,
    as_bool,
    as_queue,
    as_rate,
    ros_type_hint,
    zero_queue_hint,
)
from ros_gz_bridge_py.errors import ConfigError

#: "No value" for a queue parameter, as the C++ node declares it.
_UNSET_QUEUE = -1


class _Bridge:
    """Reads the ``bridges.<name>.*`` parameters of one bridge."""

    def __init__(self, name: str, get: Callable[[str], object | None], warnings: list[str]) -> None:
        self.name = name
        self.source = f"parameter bridges.{name}"
        self._get = get
        self._warnings = warnings

    def error(self, text: str) -> ConfigError:
        return ConfigError(f"Bridge {self.name} {text}", self.source)

    def warn(self, text: str) -> None:
        self._warnings.append(f"{self.source}: {text}")

    def raw(self, key: str) -> object | None:
        return self._get(f"bridges.{self.name}.{key}")

    def text(self, key: str) -> str:
        """A string parameter; "" when it is not set."""
        value = self.raw(key)
        if value is None:
            return ""
        if not isinstance(value, str):
            msg = f"sets {key} to {value!r}; it must be a string."
            raise self.error(msg)
        return value

    def required(self, key: str) -> str:
        value = self.text(key)
        if not value:
            msg = f"does not set required parameter {key}."
            raise self.error(msg)
        return value

    def queue(self, key: str) -> int | None:
        value = self.raw(key)
        if value is None or value == _UNSET_QUEUE:
            return None
        try:
            depth = as_queue(key, value)
        except ConfigError as err:
            msg = f"has an invalid value: {err.message}; use -1 for the default."
            raise self.error(msg) from err
        if depth == 0:
            self.warn(zero_queue_hint(key))
        return depth

    def rate(self) -> float | None:
        value = self.raw("max_rate")
        if value is None:
            return None
        try:
            return as_rate("max_rate", value)
        except ConfigError as err:
            msg = f"has an invalid value: {err.message}."
            raise self.error(msg) from err

    def lazy(self) -> bool | None:
        value = self.raw("lazy")
        if value is None:
            return None
        try:
            return as_bool("lazy", value)
        except ConfigError as err:
            msg = f"has an invalid value: {err.message}."
            raise self.error(msg) from err


def _parse_topic(bridge: _Bridge, ros_type: str) -> TopicBridgeSpec | None:
    gz_topic = bridge.required("gz_topic_name")
    gz_type = bridge.required("gz_type_name")
    direction_text = bridge.text("direction") or Direction.BIDIRECTIONAL.value
    if direction_text == "NONE":
        return None
    try:
        direction = Direction(direction_text)
    except ValueError:
        msg = f"defines unknown direction {direction_text}."
        raise bridge.error(msg) from None
    qos_profile = bridge.text("qos_profile") or None
    if qos_profile is not None and qos_profile not in QOS_PROFILE_NAMES:
        msg = f"defines unknown QoS profile {qos_profile}."
        raise bridge.error(msg)
    return TopicBridgeSpec(
        ros_topic=bridge.text("ros_topic_name"),
        gz_topic=gz_topic,
        ros_type=ros_type,
        gz_type=gz_type,
        direction=direction,
        lazy=bridge.lazy(),
        publisher_queue=bridge.queue("publisher_queue"),
        subscriber_queue=bridge.queue("subscriber_queue"),
        qos_profile=qos_profile,
        frame_id=bridge.text("frame_id") or None,
        max_rate=bridge.rate(),
        source=bridge.source,
    )


def _parse_bridge(bridge: _Bridge) -> BridgeSpec | None:
    ros_type = bridge.required("ros_type_name")
    if bool(bridge.text("ros_topic_name")) == bool(bridge.text("service_name")):
        msg = "needs to set exactly one of ros_topic_name or service_name."
        raise bridge.error(msg)
    if hint := ros_type_hint(ros_type):
        bridge.warn(hint)
    if bridge.text("service_name"):
        return ServiceBridgeSpec(
            service=bridge.text("service_name"),
            ros_type=ros_type,
            gz_req_type=bridge.required("gz_req_type_name"),
            gz_rep_type=bridge.required("gz_rep_type_name"),
            source=bridge.source,
        )
    spec = _parse_topic(bridge, ros_type)
    if spec is None:
        bridge.warn("direction NONE bridges nothing; the bridge is skipped")
    return spec


def parse_parameter_bridges(
    names: Sequence[str], get: Callable[[str], object | None]
) -> ParseResult:
    """Parse the bridges listed in ``bridge_names``.

    ``get("bridges.<name>.<key>")`` returns the parameter's value, or None when it is not set.
    An invalid bridge is reported in ``errors`` and skipped; the others are kept.
    """
    specs: list[BridgeSpec] = []
    errors: list[ConfigError] = []
    warnings: list[str] = []
    for name in names:
        try:
            spec = _parse_bridge(_Bridge(name, get, warnings))
        except ConfigError as err:
            errors.append(err)
            continue
        if spec is not None:
            specs.append(spec)
    return ParseResult(tuple(specs), tuple(errors), tuple(warnings))

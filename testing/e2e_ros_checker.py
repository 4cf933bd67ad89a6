"""The ROS side of the end-to-end tests: one rclpy process that subscribes and publishes.

Usage: ``python e2e_ros_checker.py SPEC`` where SPEC is JSON::

    {"subscribe": [[topic, type], ...],
     "publish": [[topic, type, {field: value, ...}], ...],
     "seconds": 60}

Subscriptions are best effort and volatile, so they match any publisher QoS. Each publisher
sends its message at 5 Hz for the whole run. Output, one record per line: ``READY``, then
``MATCHED <topic>`` when a publisher first sees a subscriber other than ours, and
``MSG {"topic": ..., "msg": {...}}`` for every message that differs from those seen before
on its topic (at most 20 per topic). The process ends after ``seconds`` or on SIGTERM/SIGINT.
"""

from __future__ import annotations

import array
import importlib
import json
import sys
import time
from typing import Any

import numpy as np
import rclpy
from rclpy.node import Node
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
from rclpy.signals import SignalHandlerOptions

from ros_gz_bridge_py.ros.stop_signal import StopSignal

_DISTINCT_PER_TOPIC = 20
_PUBLISH_PERIOD = 0.2


def message_type(name: str) -> Any:
    """The rclpy class of ``pkg/msg/Name``."""
    package, _, type_name = name.split("/")
    return getattr(importlib.import_module(f"{package}.msg"), type_name)


def to_plain(value: Any) -> Any:
    """A ROS message as JSON-ready dicts, lists and scalars."""
    if hasattr(value, "get_fields_and_field_types"):
        return {name: to_plain(getattr(value, name)) for name in value.get_fields_and_field_types()}
    if isinstance(value, array.array | np.ndarray):
        return value.tolist()
    if isinstance(value, list | tuple):
        return [to_plain(item) for item in value]
    if isinstance(value, bytes):
        return list(value)
    if isinstance(value, np.generic):
        return value.item()
    return value


def fill(msg: Any, values: dict[str, Any]) -> Any:
    """Set the fields of ``msg`` from nested dicts; returns ``msg``."""
    for name, value in values.items():
        if isinstance(value, dict):
            fill(getattr(msg, name), value)
        else:
            setattr(msg, name, value)
    return msg


def emit(text: str) -> None:
    sys.stdout.write(text + "\n")
    sys.stdout.flush()


class Checker:
    """Subscriptions that report distinct messages, publishers that repeat one message."""

    def __init__(self, node: Node, spec: dict[str, Any]) -> None:
        self._seen: dict[str, set[str]] = {}
        qos = QoSProfile(
            depth=10,
            reliability=ReliabilityPolicy.BEST_EFFORT,
            durability=DurabilityPolicy.VOLATILE,
        )
        for topic, type_name in spec.get("subscribe", []):
            self._seen[topic] = set()
            node.create_subscription(
                message_type(type_name), topic, lambda msg, t=topic: self._report(t, msg), qos
            )
        self._publishers: list[tuple[Any, Any, str]] = []
        self._matched: set[str] = set()
        for topic, type_name, values in spec.get("publish", []):
            publisher = node.create_publisher(message_type(type_name), topic, 10)
            self._publishers.append((publisher, fill(message_type(type_name)(), values), topic))
        node.create_timer(_PUBLISH_PERIOD, self._publish)

    def _report(self, topic: str, msg: Any) -> None:
        text = json.dumps({"topic": topic, "msg": to_plain(msg)})
        seen = self._seen[topic]
        if text not in seen and len(seen) < _DISTINCT_PER_TOPIC:
            seen.add(text)
            emit(f"MSG {text}")

    def _publish(self) -> None:
        for publisher, msg, topic in self._publishers:
            others = publisher.get_subscription_count() - (1 if topic in self._seen else 0)
            if others > 0 and topic not in self._matched:
                self._matched.add(topic)
                emit(f"MATCHED {topic}")
            publisher.publish(msg)


def main() -> int:
    spec = json.loads(sys.argv[1])
    with StopSignal() as stop:
        rclpy.init(signal_handler_options=SignalHandlerOptions.NO)
        node = Node("e2e_ros_checker")
        Checker(node, spec)
        emit("READY")
        end = time.monotonic() + float(spec.get("seconds", 60))
        try:
            while not stop.requested and time.monotonic() < end:
                rclpy.spin_once(node, timeout_sec=0.05)
        finally:
            node.destroy_node()
            rclpy.try_shutdown()
        return 0


if __name__ == "__main__":
    sys.exit(main())

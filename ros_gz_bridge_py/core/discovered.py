"""Bridges that follow Gazebo discovery: ``auto_bridge`` and the YAML entries it completes.

A :class:`DiscoveredBridges` scans the partition's graph (``GzNode.graph``) on a wall-clock
timer of the bridge's ROS node, plans what to bridge (``discovery_plan.py``) and makes the
:class:`~ros_gz_bridge_py.core.bridge.Bridge` follow: a topic that appears gets its bridge,
one whose Gazebo endpoints are gone loses it (its ROS topic goes with it), one whose type or
direction changed is bridged anew. Bridges it did not make are never touched. Why a topic is
not bridged is logged once per topic and reason.
"""

from __future__ import annotations

import time
from collections.abc import Sequence
from typing import Any

from rclpy.clock import Clock, ClockType

from ros_gz_bridge_py.config import TopicBridgeSpec
from ros_gz_bridge_py.config.discovered import AutoBridgeRules
from ros_gz_bridge_py.config.patterns import TopicPattern
from ros_gz_bridge_py.core.bridge import Bridge, BridgeHandle
from ros_gz_bridge_py.core.discovery_plan import Plan, plan, sightings
from ros_gz_bridge_py.core.explain import gazebo_name
from ros_gz_bridge_py.errors import ConfigError
from ros_gz_bridge_py.transport.api import PUBLISHER, GraphEndpoint

#: Seconds between two scans of the graph (a new topic is bridged within about this long
#: of discovery hearing of it).
SCAN_PERIOD = 0.5
#: Seconds between two requests to Gazebo peers to list their subscriptions (gz-transport 13+
#: answer with their types) while some subscriber's type is unknown; a new peer process is
#: asked at the next scan (its subscriptions may predate the bridge, and it said nothing).
ASK_EVERY = 5.0


class DiscoveredBridges:
    """Keeps the discovered bridges of ``bridge`` in step with Gazebo discovery."""

    def __init__(
        self,
        bridge: Bridge,
        *,
        patterns: Sequence[TopicPattern] = (),
        rules: AutoBridgeRules | None = None,
        period: float = SCAN_PERIOD,
    ) -> None:
        self._bridge = bridge
        self._patterns = tuple(patterns)
        self._rules = rules or AutoBridgeRules()
        self._logger = bridge.ros_node.get_logger()
        #: Gazebo topic -> the handle of the bridge made for it.
        self.current: dict[str, BridgeHandle] = {}
        self._failed: dict[str, TopicBridgeSpec] = {}
        self._said: set[tuple[str, str]] = set()
        self._untyped = False
        self._seen: tuple[list[GraphEndpoint], int] | None = None
        self._explicit: tuple[int, frozenset[str]] = (-1, frozenset())
        self._asked = (float("-inf"), -1)  # (when, how many peer processes then)
        steady = Clock(clock_type=ClockType.STEADY_TIME)
        self._timer: Any = bridge.ros_node.create_timer(period, self.scan, clock=steady)

    def scan(self) -> None:
        """Follow the graph once (the timer's callback); never raises."""
        try:
            self._scan()
        except Exception as err:
            self._logger.error(f"discovered bridging: scanning the Gazebo graph failed: {err!r}")

    def plan(self) -> Plan:
        """What the graph calls for now."""
        gz_node = self._bridge.gz_node
        found = sightings(gz_node.graph(), gz_node.partition)
        return plan(
            found,
            patterns=self._patterns,
            rules=self._rules,
            registry=self._bridge.registry,
            explicit=self._explicit_topics(),
        )

    def close(self) -> None:
        """Stop following (the bridges stay until the bridge closes)."""
        self._bridge.ros_node.destroy_timer(self._timer)

    def _scan(self) -> None:
        self._ask_subscribers()
        endpoints = self._bridge.gz_node.graph()
        seen = (endpoints, len(self._bridge.handles))
        if seen == self._seen:
            return  # nothing changed since the last scan
        self._seen = seen
        wanted = self.plan()
        for topic, handle in list(self.current.items()):
            if wanted.specs.get(topic) != handle.spec:
                del self.current[topic]
                self._bridge.remove(handle)
                self._logger.info(
                    f"Removing the discovered bridge of Gazebo {topic}: {_gone(wanted, topic)}"
                )
        for topic, spec in wanted.specs.items():
            if topic not in self.current and self._failed.get(topic) != spec:
                self._add(topic, spec)
        for topic, why in wanted.skipped.items():
            self._say_once(topic, f"Not bridging Gazebo {topic}: {why}")
        self._untyped = any(e.role != PUBLISHER and not e.msg_type for e in endpoints)

    def _ask_subscribers(self) -> None:
        """Ask peers for their subscriptions when a process came or some type is unknown
        (the transport sends nothing when gz-transport 11/12 peers would take it badly)."""
        gz_node = self._bridge.gz_node
        peers = gz_node.peer_processes()
        when, known = self._asked
        since = time.monotonic() - when
        if (peers != known and since > 1.0) or (self._untyped and since > ASK_EVERY):
            self._asked = (time.monotonic(), peers)
            gz_node.ask_subscribers()

    def _add(self, topic: str, spec: TopicBridgeSpec) -> None:
        try:
            self.current[topic] = self._bridge.add(spec)
        except ConfigError as err:
            self._failed[topic] = spec
            self._logger.error(str(err))
            return
        self._failed.pop(topic, None)
        if spec.ros_topic.lstrip("/") != topic.lstrip("/"):
            self._say_once(
                topic,
                f"Gazebo {topic} is bridged as ROS {spec.ros_topic} (a valid ROS name; README: "
                "Discovered bridging)",
            )

    def _explicit_topics(self) -> frozenset[str]:
        """Gazebo names of the bridges this class did not make (recomputed when they change)."""
        handles = self._bridge.handles
        if self._explicit[0] != len(handles):
            ours = {id(handle) for handle in self.current.values()}
            names = frozenset(
                gazebo_name(self._bridge.gz_node, h.spec.gz_topic)[1]
                for h in handles
                if isinstance(h.spec, TopicBridgeSpec) and id(h) not in ours
            )
            self._explicit = (len(handles), names)
        return self._explicit[1]

    def _say_once(self, topic: str, text: str) -> None:
        if (topic, text) not in self._said:
            self._said.add((topic, text))
            self._logger.info(text)


def _gone(wanted: Plan, topic: str) -> str:
    if topic in wanted.specs:
        return "its type or direction changed"
    return wanted.skipped.get(topic, "no other Gazebo process publishes or subscribes to it")

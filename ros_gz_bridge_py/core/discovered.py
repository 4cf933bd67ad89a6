"""Bridges that follow Gazebo discovery: ``auto_bridge`` and the YAML entries it completes.

A :class:`DiscoveredBridges` scans the partition's graph (``GzNode.graph``), and with
``auto_bridge`` the ROS publishers of the names Gazebo only subscribes to (not the bridge's
own), on a wall-clock timer of the bridge's ROS node, plans what to bridge
(``discovery_plan.py``) and makes the
:class:`~ros_gz_bridge_py.core.bridge.Bridge` follow: a topic that appears gets its bridge,
one whose Gazebo endpoints are gone loses it (its ROS topic goes with it), one whose type or
direction changed is bridged anew. Bridges it did not make are never touched. Why a topic is
not bridged is logged once per topic and reason.
"""

from __future__ import annotations

import time
from collections.abc import Iterable, Sequence
from typing import Any

from ros_gz_bridge_py.config import TopicBridgeSpec
from ros_gz_bridge_py.config.discovered import AutoBridgeRules
from ros_gz_bridge_py.config.patterns import TopicPattern
from ros_gz_bridge_py.core.bridge import Bridge, BridgeHandle
from ros_gz_bridge_py.core.discovery_plan import (
    BY_ROS_PUBLISHER,
    Plan,
    RosPublishers,
    Sighting,
    plan,
    ros_names_to_read,
    same_bridge,
    sightings,
)
from ros_gz_bridge_py.core.explain import gazebo_name
from ros_gz_bridge_py.errors import ConfigError
from ros_gz_bridge_py.ros.quick_log import quick_logger
from ros_gz_bridge_py.ros.runtime import steady_clock
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
        self._logger = quick_logger(bridge.ros_node.get_logger())
        #: Gazebo topic -> the handle of the bridge made for it.
        self.current: dict[str, BridgeHandle] = {}
        self._failed: dict[str, TopicBridgeSpec] = {}
        self._said: set[tuple[str, str]] = set()
        self._untyped = False
        self._graph: tuple[list[GraphEndpoint], dict[str, Sighting]] = ([], {})
        self._seen: tuple[dict[str, Sighting], RosPublishers, int] | None = None
        self._explicit: tuple[int, frozenset[str]] = (-1, frozenset())
        self._asked = (float("-inf"), -1)  # (when, how many peer processes then)
        self._timer: Any = bridge.ros_node.create_timer(period, self.scan, clock=steady_clock())

    def scan(self) -> None:
        """Follow the graph once (the timer's callback); never raises."""
        try:
            self._scan()
        except Exception as err:
            self._logger.error(f"discovered bridging: scanning the Gazebo graph failed: {err!r}")

    def plan(self) -> Plan:
        """What the graph calls for now."""
        found = self._sightings(self._bridge.gz_node.graph())
        return self._plan(found, self._ros_publishers(found))

    def _plan(self, found: dict[str, Sighting], ros: RosPublishers) -> Plan:
        return plan(
            found,
            patterns=self._patterns,
            rules=self._rules,
            registry=self._bridge.registry,
            explicit=self._explicit_topics(),
            ros_publishers=ros,
        )

    def _sightings(self, endpoints: list[GraphEndpoint]) -> dict[str, Sighting]:
        """The sightings of ``endpoints`` (recomputed only when they changed)."""
        if endpoints != self._graph[0]:
            gz_node = self._bridge.gz_node
            self._graph = (
                endpoints,
                sightings(endpoints, gz_node.partition, gz_node.peer_spelling),
            )
        return self._graph[1]

    def _ros_publishers(self, found: dict[str, Sighting]) -> RosPublishers:
        if not self._rules.enabled:
            return {}
        names = ros_names_to_read(found)
        return ros_publishers(self._bridge.ros_node, names, self._bridge.own_nodes)

    def close(self) -> None:
        """Stop following (the bridges stay until the bridge closes)."""
        self._bridge.ros_node.destroy_timer(self._timer)

    def _scan(self) -> None:
        self._ask_subscribers()
        endpoints = self._bridge.gz_node.graph()
        found = self._sightings(endpoints)
        ros = self._ros_publishers(found)
        seen = (found, ros, len(self._bridge.handles))
        if seen == self._seen:
            return  # nothing changed since the last scan
        self._seen = seen
        wanted = self._plan(found, ros)
        for topic, handle in list(self.current.items()):
            spec = wanted.specs.get(topic)
            if spec is None or not same_bridge(spec, handle.spec):
                del self.current[topic]
                self._bridge.remove(handle)
                self._logger.info(
                    f"Removing the discovered bridge of Gazebo {topic}: {_gone(wanted, topic)}"
                )
        for topic, spec in wanted.specs.items():
            failed = self._failed.get(topic)
            if topic not in self.current and (failed is None or not same_bridge(failed, spec)):
                self._add(topic, spec)
        for topic, why in wanted.skipped.items():
            self._say_once(topic, f"Not bridging Gazebo {topic}: {why}")
        for topic, note in wanted.notes.items():
            self._say_once(topic, f"Gazebo {topic}: {note}")
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
        if spec.discovered_by == BY_ROS_PUBLISHER:
            self._say_once(
                topic,
                f"Bridging ROS {spec.ros_topic} ({spec.ros_type}) -> Gazebo {topic} "
                f"({spec.gz_type}): its Gazebo subscribers tell no type, {BY_ROS_PUBLISHER}",
            )
        if spec.ros_topic.lstrip("/") != topic.lstrip("/"):
            self._say_once(
                topic,
                f"Gazebo {topic} is bridged as ROS {spec.ros_topic} (a valid ROS name; "
                "docs/many-topics.md: Discovered bridging)",
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


def ros_publishers(
    ros_node: Any, names: Iterable[str], own_nodes: Iterable[tuple[str, str]]
) -> dict[str, tuple[str, ...]]:
    """The distinct types of the ROS publishers of each of ``names`` (resolved in
    ``ros_node``'s namespace) that no node of ``own_nodes`` (name, namespace) owns; names
    without such publishers left out."""
    wanted = list(names)
    if not wanted:
        return {}  # no graph query: the scan runs every SCAN_PERIOD
    own = set(own_nodes)
    existing = {name for name, _ in ros_node.get_topic_names_and_types()}
    found = {}
    for name in wanted:
        resolved = ros_node.resolve_topic_name(name)
        if resolved not in existing:
            continue
        types = [
            info.topic_type
            for info in ros_node.get_publishers_info_by_topic(resolved)
            if (info.node_name, info.node_namespace) not in own
        ]
        if types:
            found[name] = tuple(dict.fromkeys(types))
    return found


def _gone(wanted: Plan, topic: str) -> str:
    if topic in wanted.specs:
        return "its type or direction changed"
    return wanted.skipped.get(topic, "no other Gazebo process publishes or subscribes to it")

"""The bridge explains its channels: gathers what discovery and the ROS graph show, sets each
channel's flow state and causes (``diagnosis.py``), and logs each cause once.

A cause is logged once it has lasted two evaluations (discovery needs a moment to see
everything), at most once a minute while it comes and goes, and again only after it went
away. "No Gazebo peer at all" concerns every channel, so it is said once for the bridge. The
half of a bidirectional entry that waits for a side not there while the other half has
carried is not warned about: an '@' entry's Gazebo topic often has no subscriber at all.
"""

from __future__ import annotations

import dataclasses
import time
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass, field
from typing import Any

from rclpy.qos import QoSProfile

from ros_gz_bridge_py.config import Direction
from ros_gz_bridge_py.converters.registry import Registry
from ros_gz_bridge_py.core.channel import Channel, ChannelState
from ros_gz_bridge_py.core.diagnosis import (
    ENTRY_QOS_SETTING,
    Finding,
    Flow,
    RosEndpoint,
    Situation,
    TypeHints,
    findings,
    flow,
    wanted_role,
)
from ros_gz_bridge_py.core.ros_endpoints import as_the_graph_shows, ros_endpoints
from ros_gz_bridge_py.core.ros_to_gz import RosToGzChannel
from ros_gz_bridge_py.core.similar_topics import Offered, offered_by_others
from ros_gz_bridge_py.transport import GzNode
from ros_gz_bridge_py.transport.api import GraphEndpoint
from ros_gz_bridge_py.transport.names import decompose, fully_qualified_name

#: Seconds between two evaluations of every channel.
EXPLAIN_PERIOD = 2.0
#: A channel is not judged before it is this old: discovery hears every peer within ~3 s.
#: Nor is "no Gazebo process at all" said before the bridge listened this long.
WARM_UP = 3.0
#: A cause is logged once it was seen in two evaluations, this far apart at least.
CONFIRM_AFTER = EXPLAIN_PERIOD / 2
#: A cause that went away and came back is logged again after this long at the earliest.
RELOG_AFTER = 60.0
#: How often the bridge may ask Gazebo peers to list their subscriptions.
ASK_SUBSCRIBERS_EVERY = 10.0
#: Seconds a channel's ROS endpoints are reused while the graph's nodes and the topic's count
#: of them stay the same (either changing asks them anew at the next pass): asking every
#: channel's every 2 s was 8 ms a pass for a fleet of 25 robots, most of the bridge's Python.
ROS_ENDPOINTS_REFRESH = 10.0
#: Causes that concern the whole bridge rather than one channel (logged once).
BRIDGE_WIDE = frozenset({"no-peer", "no-peer:overdue"})
#: Seconds after which a Gazebo side still absent is a fault (WARN), no longer a simulator
#: that starts after the bridge: the bridge listened this long without hearing any Gazebo
#: process, or the partition's other topics have been there this long (and the channel too).
PATIENCE = 30.0
#: Seconds after which the processes heard in the bridge's partition are a simulator, whose
#: loss is said at once and as such (a tool such as `gz topic -e` comes and goes sooner).
SIMULATOR_AFTER = 10.0


def type_hints(
    registry: Registry, types_fixed_by: str = "", qos_setting: str = ENTRY_QOS_SETTING
) -> TypeHints:
    """The registry's answers about types, as the findings' fixes need them."""
    return TypeHints(
        pairs=lambda ros_type, gz_type: registry.find(ros_type, gz_type) is not None,
        ros_types_for=registry.ros_types_for,
        gz_types_for=registry.gz_types_for,
        types_fixed_by=types_fixed_by,
        qos_setting=qos_setting,
    )


def gazebo_name(gz_node: GzNode, topic: str) -> tuple[str, str]:
    """(partition, topic name) as discovery shows ``topic`` of ``gz_node``."""
    partition = getattr(gz_node, "partition", "")
    namespace = getattr(gz_node, "namespace", "")
    fqn = fully_qualified_name(partition, namespace, topic)
    _, name = decompose(fqn) or ("", topic)
    return partition, name


@dataclass
class _Seen:
    """What the explainer remembers of one channel between evaluations."""

    started: float
    #: (partition, topic name) as discovery shows the channel's Gazebo topic.
    gz_name: tuple[str, str]
    #: The channel's profile as the ROS graph shows it.
    qos: QoSProfile
    count: int = 0
    changed: float | None = None
    interval: float | None = None
    #: Finding key -> when it was first seen in the current run of evaluations.
    present: dict[str, float] = field(default_factory=dict)
    #: Finding key -> when it was last logged.
    logged: dict[str, float] = field(default_factory=dict)
    #: Keys logged during their current presence.
    announced: set[str] = field(default_factory=set)
    #: The ROS endpoints last asked, what they were asked for (the graph's nodes, the topic's
    #: count of them) and when.
    endpoints: list[RosEndpoint] = field(default_factory=list)
    endpoints_key: tuple[frozenset[tuple[str, str]], int] | None = None
    endpoints_at: float = 0.0
    #: A cause of its own was logged since it last flowed.
    waited: bool = False
    #: The namespace of the bridge's node (asked once, not at every pass).
    ros_namespace: str = ""


class Explainer:
    """Evaluates channels and logs their causes; one per bridge.

    ``log`` takes the misconfigurations (a WARN); ``note`` the sides that are not there yet,
    which are no fault (an INFO: a simulator that starts after the bridge is the usual case),
    and defaults to ``log``."""

    def __init__(
        self,
        gz_node: GzNode,
        registry: Registry,
        own_nodes: Iterable[tuple[str, str]],
        log: Callable[[str], None],
        now: Callable[[], float] = time.monotonic,
        *,
        note: Callable[[str], None] | None = None,
        types_fixed_by: str = "",
        qos_setting: str = ENTRY_QOS_SETTING,
    ) -> None:
        self._gz = gz_node
        self._hints = type_hints(registry, types_fixed_by, qos_setting)
        self._own = frozenset(own_nodes)
        self._log = log
        self._note = note or log
        self._now = now
        self._started = now()
        self._seen: dict[int, _Seen] = {}
        self._bridge_announced: set[str] = set()
        self._bridge_logged: dict[str, float] = {}
        self._partition = getattr(gz_node, "partition", "").strip("/")
        #: Since when other processes have endpoints in the bridge's partition (None: not now).
        self._alive_since: float | None = None
        #: Since when Gazebo processes are heard (None: none now), since when none is.
        self._peers_since: float | None = None
        self._quiet_since = self._started
        #: The processes last lost were a simulator (:data:`SIMULATOR_AFTER`).
        self._simulator_lost = False
        self._no_peer_said = False
        self._asked = float("-inf")

    def evaluate(self, channels: Sequence[Channel]) -> None:
        """Set every channel's ``flow`` and ``findings``; log the causes that are new."""
        now = self._now()
        alive = {id(channel) for channel in channels}
        self._seen = {key: seen for key, seen in self._seen.items() if key in alive}
        if not channels:
            return
        self._bridge_announced &= {
            f.key for channel in channels for f in channel.findings if f.key in BRIDGE_WIDE
        }
        peers = self._gz.peer_processes()
        listening = self._gz.listening()
        offered: Offered | None = None
        # One snapshot of the Gazebo graph for every channel (observe per channel would scan
        # it once per channel: with 1,000 discovered topics, most of a core).
        everything = self._gz.graph()
        graph: dict[str, list[GraphEndpoint]] = {}
        for endpoint in everything:
            graph.setdefault(endpoint.topic, []).append(endpoint)
        self._follow_peers(everything, peers, now)
        nodes = self._ros_others(channels[0].ctx.ros_node)
        carried: dict[int, list[Channel]] = {}  # spec -> its channels that passed a message
        for channel in channels:
            if channel.stats.received:
                carried.setdefault(id(channel.spec), []).append(channel)
        judged: list[tuple[Channel, _Seen, list[Finding], bool]] = []
        for channel in channels:
            seen = self._seen.get(id(channel)) or self._remember(channel, now)
            self._count(seen, channel, now)
            # A '@' entry's half that waits while the other one has carried: a side not
            # there (a Gazebo topic nobody subscribes to) is the usual case, never a fault.
            quiet = any(other is not channel for other in carried.get(id(channel.spec), ()))
            situation = self._situation(
                channel,
                seen,
                now,
                (peers, listening),
                graph,
                ros_nodes=nodes,
                overdue=not quiet and self._overdue(seen, peers, now),
            )
            if (
                situation.direction is Direction.ROS_TO_GZ
                and not situation.gz_subscriber_registered
            ):
                self._ask_subscribers(now)
            found = findings(situation, self._hints)
            if any(f.key.startswith("gz-absent") for f in found):
                offered = offered or offered_by_others(everything, self._partition)
                role = wanted_role(situation.direction)
                situation = dataclasses.replace(
                    situation,
                    gz_topics=offered.topics(role),
                    gz_typed=offered.of_type(role, situation.gz_type),
                )
                found = findings(situation, self._hints)
            channel.flow = flow(situation)
            channel.findings = found
            judged.append((channel, seen, found, quiet))
        for channel, seen, found, quiet in judged:
            if now - seen.started >= WARM_UP:
                said = [finding for finding in found if finding.fault] if quiet else found
                self._report(channel, seen, said, now)

    def _follow_peers(self, graph: Sequence[GraphEndpoint], peers: int, now: float) -> None:
        """Note since when the bridge's partition has other processes' endpoints and since
        when processes are heard or none is, and say once that Gazebo is heard after
        "nothing can flow" was said."""
        was_alive = self._alive_since
        if any(endpoint.partition.strip("/") == self._partition for endpoint in graph):
            self._alive_since = now if self._alive_since is None else self._alive_since
        else:
            self._alive_since = None
        if not peers:
            if self._peers_since is not None:  # lost since the last look
                self._simulator_lost = (
                    was_alive is not None and now - self._peers_since >= SIMULATOR_AFTER
                )
                if self._simulator_lost:
                    self._bridge_logged.clear()  # a simulator's loss is said at once
                self._peers_since, self._quiet_since = None, now
            return
        self._simulator_lost = False
        self._peers_since = now if self._peers_since is None else self._peers_since
        if now - self._peers_since < CONFIRM_AFTER:
            return
        if self._no_peer_said:
            self._no_peer_said = False
            heard = "1 process" if peers == 1 else f"{peers} processes"
            self._note(f"Gazebo Transport heard now ({heard} in any partition)")

    def _overdue(self, seen: _Seen, peers: int, now: float) -> bool:
        """Whether the channel's Gazebo side had :data:`PATIENCE` to be there."""
        if now - seen.started < PATIENCE:
            return False
        if not peers:  # counted from when the last were lost: a simulator restarting
            return now - self._quiet_since >= PATIENCE
        return self._alive_since is not None and now - self._alive_since >= PATIENCE

    def _ros_others(self, ros_node: Any) -> frozenset[tuple[str, str]] | None:
        """The ROS graph's nodes, or None when it shows none that is not the bridge's: then no
        channel has a ROS endpoint to check, and the pass asks no topic's endpoints (2 µs
        instead of about 20 µs per channel: most of a fleet's explanation pass at rest)."""
        names = frozenset(ros_node.get_node_names_and_namespaces())
        return None if names <= self._own else names

    def _ros_endpoints(
        self, channel: Channel, seen: _Seen, now: float, nodes: frozenset[tuple[str, str]]
    ) -> list[RosEndpoint]:
        """The channel's ROS endpoints, asked again only when the graph's nodes or the topic's
        count of them changed, or :data:`ROS_ENDPOINTS_REFRESH` after the last ask (a reader
        replaced by another in a node that stays, between two passes)."""
        ros_node, topic = channel.ctx.ros_node, channel.ros_topic
        to_ros = channel.direction is Direction.GZ_TO_ROS
        count = ros_node.count_subscribers(topic) if to_ros else ros_node.count_publishers(topic)
        key = (nodes, count)
        if key != seen.endpoints_key or now - seen.endpoints_at >= ROS_ENDPOINTS_REFRESH:
            seen.endpoints = ros_endpoints(ros_node, channel.direction, topic, seen.qos, self._own)
            seen.endpoints_key, seen.endpoints_at = key, now
        return seen.endpoints

    def _remember(self, channel: Channel, now: float) -> _Seen:
        """A channel's first evaluation; what does not change is worked out once (at rest, a
        fleet's 201 channels every 2 s made this a third of the bridge's CPU)."""
        name = gazebo_name(self._gz, channel.spec.gz_topic)
        # Counted from 0: a channel that passed messages before its first evaluation (2 s
        # after the bridge started) is flowing at once, not "stalled" in its first status.
        namespace = channel.ctx.ros_node.get_namespace()
        seen = _Seen(now, name, as_the_graph_shows(channel.qos), ros_namespace=namespace)
        self._seen[id(channel)] = seen
        return seen

    def _count(self, seen: _Seen, channel: Channel, now: float) -> None:
        count = channel.stats.published  # passed on: failing every message is no flow
        if count != seen.count:
            if seen.changed is not None:
                seen.interval = (now - seen.changed) / (count - seen.count)
            seen.count, seen.changed = count, now

    def _situation(
        self,
        channel: Channel,
        seen: _Seen,
        now: float,
        gz_side: tuple[int, str],
        graph: dict[str, list[GraphEndpoint]],
        *,
        ros_nodes: frozenset[tuple[str, str]] | None,
        overdue: bool,
    ) -> Situation:
        """``gz_side``: (peer processes, where the node listens); ``graph``: the endpoints of
        other processes by topic name (``GzNode.graph``); ``ros_nodes``: the ROS graph's nodes,
        None when it shows none but the bridge's (:meth:`_ros_others`); ``overdue``: its Gazebo
        side had :data:`PATIENCE` to be there."""
        spec = channel.spec
        peers, listening = gz_side
        partition, name = seen.gz_name
        registered = isinstance(channel, RosToGzChannel) and channel.gazebo_subscribed()
        return Situation(
            direction=channel.direction,
            ros_topic=channel.ros_topic,
            ros_type=spec.ros_type,
            gz_topic=name,
            gz_type=spec.gz_type,
            partition=partition,
            gz_endpoints=graph.get(name, []),
            ros_endpoints=[]
            if ros_nodes is None
            else self._ros_endpoints(channel, seen, now, ros_nodes),
            gz_peers=peers,
            listening=listening,
            gz_subscriber_registered=registered,
            input_open=channel.state is ChannelState.ACTIVE,
            since_message=None if seen.changed is None else now - seen.changed,
            interval=seen.interval,
            discovered_by=spec.discovered_by,
            peers_settled=now - self._started >= WARM_UP,
            bidirectional=spec.direction is Direction.BIDIRECTIONAL,
            ros_namespace=seen.ros_namespace,
            overdue=overdue,
            peers_lost=not peers and self._simulator_lost,
        )

    def _ask_subscribers(self, now: float) -> None:
        if now - self._asked >= ASK_SUBSCRIBERS_EVERY:
            self._asked = now
            self._gz.ask_subscribers()

    def _report(self, channel: Channel, seen: _Seen, found: list[Finding], now: float) -> None:
        keys = {finding.key for finding in found}
        if seen.waited and not keys and channel.flow is Flow.FLOWING:
            seen.waited = False  # what was said of it no longer holds: say so
            self._note(f"{channel.describe()}: flowing")
        seen.present = {key: seen.present.get(key, now) for key in keys}
        seen.announced &= keys
        for finding in found:
            key = finding.key
            if key in seen.announced or now - seen.present[key] < CONFIRM_AFTER:
                continue
            if key in BRIDGE_WIDE:
                if key not in self._bridge_announced:
                    if now - self._bridge_logged.get(key, float("-inf")) < RELOG_AFTER:
                        continue  # it came and went lately (a `gz topic -l` heard): said already
                    self._bridge_logged[key] = now
                    self._bridge_announced.add(key)
                    self._no_peer_said = True
                    say = self._log if finding.fault else self._note
                    say(f"Nothing can flow: {finding.text}")
                seen.announced.add(key)
                continue
            if now - seen.logged.get(key, float("-inf")) < RELOG_AFTER:
                continue  # it came and went lately: said already
            seen.logged[key] = now
            seen.announced.add(key)
            seen.waited = True
            state = channel.flow.value if channel.flow is not None else "starting"
            say = self._log if finding.fault else self._note
            say(f"{channel.describe()}: {state}: {finding.text}")

"""``parameter_bridge --check``: would each configured entry carry messages, and if not, why.

It takes the same arguments, ``--ros-args`` and configuration as a normal run, bridges nothing,
listens to Gazebo discovery (every partition) and the ROS graph for a few seconds, and prints
per entry what each side shows and the fix for every cause that keeps it from working
(``diagnosis.py``). ROS->Gazebo entries are announced to Gazebo (nothing is published), so that
Gazebo subscribers show whether they take the type. With ``auto_bridge`` or entries that
discovery completes, what discovered bridging would bridge (planned half-way through) is
checked too, each entry with the rule that chose its types. Exit status 1 when an entry cannot
work. SIGINT or SIGTERM end the check at once, without a report (exit status 0).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any, TextIO

from rclpy.qos import QoSProfile
from rclpy.qos_overriding_options import InvalidQosOverridesError

from ros_gz_bridge_py.app.discover import listen
from ros_gz_bridge_py.config import BridgeSpec, Direction, ServiceBridgeSpec, TopicBridgeSpec
from ros_gz_bridge_py.converters.registry import Registry
from ros_gz_bridge_py.core.diagnosis import (
    Finding,
    RosEndpoint,
    Situation,
    findings,
    takes_ours,
    wanted_role,
)
from ros_gz_bridge_py.core.explain import gazebo_name, type_hints
from ros_gz_bridge_py.core.ros_endpoints import as_the_graph_shows, ros_endpoints
from ros_gz_bridge_py.core.similar_topics import Offered, offered_by_others
from ros_gz_bridge_py.core.spec_checks import refused_name_fix
from ros_gz_bridge_py.errors import RCL_SOURCE_LOCATION, ConfigError, TransportError
from ros_gz_bridge_py.msgs.names import same_message
from ros_gz_bridge_py.ros.qos import (
    apply_publisher_overrides,
    apply_subscription_overrides,
    endpoint_qos,
    gz_to_ros_publisher_qos,
)
from ros_gz_bridge_py.ros.stop_signal import StopSignal
from ros_gz_bridge_py.transport import GzNode, Publisher
from ros_gz_bridge_py.transport.api import GraphEndpoint

#: Seconds ``--check`` listens by default: discovery re-announces every second, the ROS graph
#: settles within about two.
DEFAULT_SECONDS = 5.0
#: What a check stopped by SIGINT or SIGTERM prints instead of its report: the report of a
#: shorter listen would show as missing what it had no time to hear.
STOPPED = "Stopped (SIGINT or SIGTERM) before the end of listening: nothing checked"


@dataclass(frozen=True)
class Sides:
    """The two ends the check looks at, and the converter registry for the fixes."""

    ros_node: Any
    gz_node: GzNode
    registry: Registry


@dataclass(frozen=True)
class EntryReport:
    """What ``--check`` found for one direction of one entry (or a service entry)."""

    title: str
    seen: tuple[str, ...]
    problems: tuple[str, ...]


def run_check(
    sides: Sides,
    specs: Sequence[BridgeSpec],
    seconds: float,
    *,
    out: TextIO,
    spin_once: Any,
    discovered: Callable[[], Sequence[TopicBridgeSpec]] = list,
    stop: StopSignal | None = None,
) -> int:
    """Listen for ``seconds`` (spinning the ROS node with ``spin_once``), then print one
    report per entry to ``out``; 1 if any cannot work. ``discovered``: the entries discovered
    bridging would add, asked for half-way through and checked with the others. SIGINT or
    SIGTERM (``stop``, the executable's) end the check at once without a report, with the
    status of an interrupted run: 0."""
    gz_node = sides.gz_node
    specs = list(specs)
    probes: dict[int, Publisher | None] = {}
    try:
        _announce(gz_node, specs, probes, out)
        print(
            f"Listening for {seconds:g} s: Gazebo ({gz_node.listening()}) and the ROS graph ...",
            file=out,
            flush=True,
        )
        listened = listen(seconds / 2, spin_once, stop)
        if listened:
            gz_node.ask_subscribers()
            specs += discovered()
            _announce(gz_node, specs, probes, out)
            listened = listen(seconds / 2, spin_once, stop)
        if not listened:
            print(STOPPED, file=out)
            return 0
        reports = _reports(sides, specs, probes)
    finally:
        for probe in probes.values():
            if probe is not None:
                probe.close()
    return _print_reports(reports, out)


def _announce(
    gz_node: GzNode, specs: Sequence[BridgeSpec], probes: dict[int, Publisher | None], out: TextIO
) -> None:
    """Announce to Gazebo the ROS->Gazebo entries not yet in ``probes`` (None: it failed)."""
    for index, spec in enumerate(specs):
        if (
            isinstance(spec, TopicBridgeSpec)
            and spec.direction is not Direction.GZ_TO_ROS
            and index not in probes
        ):
            try:
                probe = gz_node.advertise(spec.gz_topic, spec.gz_type)
            except Exception as err:  # a bad name: reported with the entry below
                probe = None
                print(f"cannot announce {spec.gz_topic}: {err}", file=out)
            probes[index] = probe


def _reports(
    sides: Sides, specs: Sequence[BridgeSpec], probes: dict[int, Publisher | None]
) -> list[EntryReport]:
    gz_topics = offered_by_others(sides.gz_node.graph(), getattr(sides.gz_node, "partition", ""))
    reports: list[EntryReport] = []
    for index, spec in enumerate(specs):
        if isinstance(spec, ServiceBridgeSpec):
            reports.append(_service_report(sides.gz_node, sides.registry, spec))
        else:
            reports += _topic_reports(sides, spec, probes.get(index), gz_topics)
    return reports


def _print_reports(reports: Sequence[EntryReport], out: TextIO) -> int:
    """Print ``reports`` and their count; 1 if any has a problem."""
    for report in reports:
        _print_report(report, out)
    failing = sum(1 for report in reports if report.problems)
    print(
        f"{len(reports) - failing} of {len(reports)} checked can carry messages"
        + (f"; {failing} cannot (see PROBLEM lines)" if failing else ""),
        file=out,
    )
    return 1 if failing else 0


def _print_report(report: EntryReport, out: TextIO) -> None:
    print(report.title, file=out)
    for line in report.seen:
        print(f"  {line}", file=out)
    for problem in report.problems:
        print(f"  PROBLEM: {problem}", file=out)
    if not report.problems:
        print("  ok: messages can flow", file=out)


def _resolved_names(sides: Sides, spec: TopicBridgeSpec) -> tuple[str, str, str]:
    """(ROS topic, Gazebo partition, Gazebo topic) as the bridge resolves ``spec``'s names.

    Raises:
        ConfigError: a name its side refuses, said as a normal run says it.
    """
    try:
        ros_topic = str(sides.ros_node.resolve_topic_name(spec.ros_topic))
    except RuntimeError as err:  # rclpy's RCLError
        reason = RCL_SOURCE_LOCATION.sub("", str(err))
        msg = f"invalid ROS topic name {spec.ros_topic!r}: {reason}{refused_name_fix(spec, reason)}"
        raise ConfigError(msg) from None
    try:
        partition, name = gazebo_name(sides.gz_node, spec.gz_topic)
    except TransportError as err:
        msg = f"{err}{refused_name_fix(spec, str(err))}"
        raise ConfigError(msg) from None
    return ros_topic, partition, name


def _topic_reports(
    sides: Sides, spec: TopicBridgeSpec, probe: Publisher | None, gz_topics: Offered
) -> list[EntryReport]:
    ros_node, gz_node, registry = sides.ros_node, sides.gz_node, sides.registry
    own = {(ros_node.get_name(), ros_node.get_namespace())}
    where = f" ({spec.source})" if spec.source else ""
    if spec.discovered_by:
        where = f" ({spec.source}, discovered: {spec.discovered_by})"
    try:
        registry.layouts(spec.ros_type, spec.gz_type)
        ros_topic, partition, name = _resolved_names(sides, spec)
    except ConfigError as err:  # an unsupported pair of types, or an invalid name
        title = f"{spec.ros_topic} <-> {spec.gz_topic}{where}"
        return [EntryReport(title, (), (str(err.message),))]
    directions = [
        d
        for d in (Direction.GZ_TO_ROS, Direction.ROS_TO_GZ)
        if spec.direction in (d, Direction.BIDIRECTIONAL)
    ]
    gz_endpoints = gz_node.observe(spec.gz_topic)
    reports: list[EntryReport] = []
    waits: list[bool] = []
    for direction in directions:
        try:
            qos = _entry_qos(ros_node, spec, direction, ros_topic)
        except InvalidQosOverridesError as err:
            reports.append(
                EntryReport(f"{spec.ros_topic} <-> {spec.gz_topic}{where}", (), (str(err),))
            )
            waits.append(False)
            continue
        ros_side = ros_endpoints(ros_node, direction, ros_topic, as_the_graph_shows(qos), own)
        role = wanted_role(direction)
        situation = Situation(
            direction=direction,
            ros_topic=ros_topic,
            ros_type=spec.ros_type,
            gz_topic=name,
            gz_type=spec.gz_type,
            partition=partition,
            gz_endpoints=gz_endpoints,
            ros_endpoints=ros_side,
            gz_peers=gz_node.peer_processes(),
            listening=gz_node.listening(),
            gz_subscriber_registered=probe is not None and bool(probe.wire_types()),
            gz_topics=gz_topics.topics(role),
            gz_typed=gz_topics.of_type(role, spec.gz_type),
            discovered_by=spec.discovered_by,
            bidirectional=spec.direction is Direction.BIDIRECTIONAL,
            ros_namespace=ros_node.get_namespace(),
        )
        arrow = (
            f"Gazebo {name} ({spec.gz_type}) -> ROS {ros_topic} ({spec.ros_type})"
            if direction is Direction.GZ_TO_ROS
            else f"ROS {ros_topic} ({spec.ros_type}) -> Gazebo {name} ({spec.gz_type})"
        )
        found: list[Finding] = findings(situation, type_hints(registry))
        seen = (
            *_gazebo_lines(situation, direction),
            *_ros_lines(ros_side, direction),
        )
        reports.append(EntryReport(f"{arrow}{where}", seen, tuple(f.text for f in found)))
        waits.append(bool(found) and not any(f.fault for f in found))
    if len(reports) == 2 and any(not report.problems for report in reports):
        return [_waiting(r) if wait else r for r, wait in zip(reports, waits, strict=True)]
    return reports


def _waiting(report: EntryReport) -> EntryReport:
    """The half of a bidirectional entry that waits for a side not there (no fault) while
    the other half carries: a note, not a problem (a working '@' entry failed the check)."""
    notes = tuple(f"waiting, while the other direction carries: {p}" for p in report.problems)
    return EntryReport(report.title, report.seen + notes, ())


def _entry_qos(
    ros_node: Any, spec: TopicBridgeSpec, direction: Direction, ros_topic: str
) -> QoSProfile:
    """The QoS the bridge's ROS endpoint of ``spec`` would have, its ``qos_overrides`` applied
    (without them a subscriber matching the overridden profile was reported as a PROBLEM).

    Raises:
        InvalidQosOverridesError: the overrides given are refused, as the bridge refuses them.
    """
    if direction is Direction.GZ_TO_ROS:
        qos = gz_to_ros_publisher_qos(ros_topic, spec.qos_profile, spec.publisher_queue)
        apply_publisher_overrides(ros_node, ros_topic, qos)
    else:
        qos = endpoint_qos(spec.qos_profile, spec.subscriber_queue)
        apply_subscription_overrides(ros_node, ros_topic, qos)
    return qos


def _gazebo_lines(situation: Situation, direction: Direction) -> list[str]:
    role = "publisher" if direction is Direction.GZ_TO_ROS else "subscriber"
    relevant = [e for e in situation.gz_endpoints if e.role == role]
    if not relevant:
        return [f"Gazebo: no {role} of {situation.gz_topic} in any partition"]
    return [f"Gazebo: {_describe_gz(e, situation.gz_type)}" for e in relevant]


def _describe_gz(endpoint: GraphEndpoint, gz_type: str) -> str:
    kind = endpoint.msg_type or "type not announced"
    taken = ", takes ours" if endpoint.registered and takes_ours(endpoint, gz_type) else ""
    where = f" at {endpoint.location}" if endpoint.location else ""
    return (
        f"{endpoint.role} ({kind}{taken}), partition '{endpoint.partition}', "
        f"process {endpoint.process_uuid[:8]}{where}"
    )


def _ros_lines(endpoints: Sequence[RosEndpoint], direction: Direction) -> list[str]:
    role = "subscriber" if direction is Direction.GZ_TO_ROS else "publisher"
    if not endpoints:
        return [f"ROS:    no {role} yet"]
    return [f"ROS:    {role} {e.node} ({e.msg_type}, {e.qos})" for e in endpoints]


def _service_report(gz_node: GzNode, registry: Registry, spec: ServiceBridgeSpec) -> EntryReport:
    where = f" ({spec.source})" if spec.source else ""
    title = f"service {spec.service} ({spec.ros_type}){where}"
    try:
        pair = registry.get_service(spec.ros_type)
    except ConfigError as err:
        return EntryReport(title, (), (str(err.message),))
    request = spec.gz_req_type or pair.gz_req_type
    response = spec.gz_rep_type or pair.gz_rep_type
    providers = gz_node.service_info(spec.service)
    seen = tuple(f"Gazebo: provider of {p.request_type} -> {p.response_type}" for p in providers)
    if any(
        same_message(p.request_type, request) and same_message(p.response_type, response)
        for p in providers
    ):
        return EntryReport(title, seen, ())
    problem = (
        f"no Gazebo provider of {spec.service} with {request} -> {response} in partition "
        f"'{getattr(gz_node, 'partition', '')}'; calls are answered success=false until one "
        "appears"
    )
    return EntryReport(title, seen or ("Gazebo: no provider",), (problem,))

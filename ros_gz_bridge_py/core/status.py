"""Live status of a running bridge: counters per channel, on ``/diagnostics`` and as a table.

A :class:`StatusTracker` turns the cumulative counters of a
:class:`~ros_gz_bridge_py.core.bridge.Bridge` (its channels'
:class:`~ros_gz_bridge_py.core.channel.ChannelStats` and queue drops, its service bridges'
calls and failures) into one :class:`ChannelStatus` per channel, with the rate and the errors
of the period since the tracker's previous snapshot. Each consumer has its own tracker,
so the ``/diagnostics`` publisher and the table printed on SIGUSR1 never shorten each other's
periods.

Each channel also shows its flow state (waiting for Gazebo, waiting for ROS, flowing, stalled)
and, when something keeps it from carrying messages, why (``explain.py``).

Levels: WARN when a cause is a misconfiguration (another type, another partition, no Gazebo
process at all, incompatible QoS), or when errors (messages the channel could not use, by
what was wrong: ``ChannelStats.errors_by_reason``), queue drops or failed service calls
happened in the period (messages ``max_rate`` drops are counted apart, as ``rate_limited``,
and are no problem); STALE for a lazy channel whose input side is closed (nobody reads its
output) and nothing is wrong: a misconfiguration found for it still makes it WARN, since the
subscriber that opens it would get nothing; OK otherwise (a side that is not there yet is
explained, not warned about).

:func:`serve` is how both executables run a built bridge: spinning, with the table on SIGUSR1.
"""

from __future__ import annotations

import collections
import contextlib
import dataclasses
import signal
import sys
import threading
import time
from collections.abc import Callable, Iterator, Mapping
from dataclasses import dataclass
from types import FrameType
from typing import Any, TextIO

from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus, KeyValue

from ros_gz_bridge_py.core.bridge import Bridge
from ros_gz_bridge_py.core.channel import Channel, ChannelState
from ros_gz_bridge_py.core.diagnosis import Flow
from ros_gz_bridge_py.core.gz_to_ros import GzToRosChannel
from ros_gz_bridge_py.core.ros_to_gz import RosToGzChannel
from ros_gz_bridge_py.core.services import NOT_CONVERTED, ServiceBridge
from ros_gz_bridge_py.ros.runtime import (
    batch_dds_event_threads,
    make_executor,
    spin_until_stopped,
    steady_clock,
)
from ros_gz_bridge_py.ros.stop_signal import StopSignal

#: Prefix of every DiagnosticStatus name, as ``ros_gz_bridge: <direction> <ros name>``.
NAME_PREFIX = "ros_gz_bridge"
#: Topic the statuses are published on (absolute: namespaced bridges share it).
DIAGNOSTICS_TOPIC = "/diagnostics"


#: DiagnosticStatus levels (the message constants are one-byte ``bytes``).
OK: bytes = DiagnosticStatus.OK
WARN: bytes = DiagnosticStatus.WARN
STALE: bytes = DiagnosticStatus.STALE
_LEVEL_NAMES = {OK: "OK", WARN: "WARN", STALE: "STALE"}


@dataclass(frozen=True)
class ChannelStatus:
    """One channel (or service bridge) at one moment; counters are totals since start."""

    direction: str
    ros_name: str
    gz_name: str
    ros_type: str
    gz_type: str
    state: str
    received: int
    published: int
    errors: int
    dropped: int
    #: Messages (calls) received per second over the period.
    rate: float
    #: Errors plus drops during the period.
    new_problems: int
    last_error: str = ""
    #: The explainer's flow state ("" before its first evaluation, and for a service that
    #: has a Gazebo provider).
    flow: str = ""
    #: Why the channel carries nothing, one cause per line ("" when nothing is wrong).
    why: str = ""
    #: One of the causes is a misconfiguration (not just a side that is not there yet).
    fault: bool = False
    #: Messages ``max_rate`` dropped (by design: not a problem).
    rate_limited: int = 0
    #: ``errors`` by what was wrong ("undecodable payload": 3, ...), largest first.
    errors_by_reason: tuple[tuple[str, int], ...] = ()
    #: Of ``errors``, those the converter refused (the rest the transport did).
    conversion_errors: int = 0
    #: Whether the channel's messages take the native data plane (docs/native.md).
    native: bool = False
    #: ROS->GZ: messages queued at most for each Gazebo subscriber (0: none kept).
    send_queue: int = 0

    @property
    def path(self) -> str:
        """``native`` or ``python``: how the channel's messages travel."""
        return "native" if self.native else "python"

    def error_summary(self) -> str:
        """``"3 undecodable payload, 1 wrong type"`` ("" without errors)."""
        return ", ".join(f"{count} {reason}" for reason, count in self.errors_by_reason)

    @property
    def name(self) -> str:
        return f"{NAME_PREFIX}: {self.direction} {self.ros_name}"

    @property
    def level(self) -> bytes:
        if self.fault or self.new_problems:
            return WARN
        if self.state == ChannelState.LAZY_IDLE.value:
            return STALE
        return OK

    @property
    def level_name(self) -> str:
        return _LEVEL_NAMES[self.level]

    def message(self) -> str:
        if self.why:
            return f"{self.flow}: {self.why}"
        if self.level == STALE:
            return "lazy: no subscribers, input side closed"
        if self.level == WARN:
            text = f"{self.new_problems} errors/drops in the last period"
            text = f"{text}: {self.last_error}" if self.last_error else text
            if self.errors_by_reason:
                text += f" (errors since start: {self.error_summary()})"
            return text
        return "ok"

    def values(self) -> dict[str, str]:
        """The key-values published in the DiagnosticStatus."""
        return {
            "direction": self.direction,
            "ros_name": self.ros_name,
            "gz_name": self.gz_name,
            "ros_type": self.ros_type,
            "gz_type": self.gz_type,
            "state": self.state,
            "received": str(self.received),
            "published": str(self.published),
            "errors": str(self.errors),
            "conversion_errors": str(self.conversion_errors),
            **{f"errors: {reason}": str(count) for reason, count in self.errors_by_reason},
            "dropped": str(self.dropped),
            "rate_limited": str(self.rate_limited),
            "rate_hz": f"{self.rate:.2f}",
            "last_error": self.last_error,
            "flow": self.flow,
            "why": self.why,
            "path": self.path,
            **({"send_queue": str(self.send_queue)} if self.send_queue else {}),
        }


@dataclass(frozen=True)
class _Totals:
    received: int
    problems: int


class StatusTracker:
    """Snapshots of a bridge's counters, with rates over the time since the previous one."""

    def __init__(self, bridge: Bridge, now: Callable[[], float] = time.monotonic) -> None:
        self._bridge = bridge
        self._now = now
        self._last_time = now()
        self._last: dict[int, _Totals] = {}

    def snapshot(self) -> list[ChannelStatus]:
        """Every channel and service bridge of the bridge, in creation order."""
        now = self._now()
        elapsed = max(now - self._last_time, 1e-9)
        self._last_time = now
        previous, self._last = self._last, {}
        statuses = []
        for key, status in self._raw_statuses():
            before = previous.get(key, _Totals(0, 0))
            problems = status.errors + status.dropped
            self._last[key] = _Totals(status.received, problems)
            statuses.append(
                dataclasses.replace(
                    status,
                    rate=(status.received - before.received) / elapsed,
                    new_problems=problems - before.problems,
                )
            )
        return statuses

    def _raw_statuses(self) -> Iterator[tuple[int, ChannelStatus]]:
        for channel in self._bridge.channels:
            yield id(channel), channel_status(channel)
        for service in self._bridge.services:
            yield id(service), service_status(service)


def channel_status(channel: Channel) -> ChannelStatus:
    """The totals of one topic channel (period fields zero)."""
    stats = channel.stats
    return ChannelStatus(
        direction="GZ->ROS" if isinstance(channel, GzToRosChannel) else "ROS->GZ",
        ros_name=channel.ros_topic,
        gz_name=channel.spec.gz_topic,
        ros_type=channel.spec.ros_type,
        gz_type=channel.spec.gz_type,
        state=channel.state.value,
        received=stats.received,
        published=stats.published,
        errors=stats.errors,
        dropped=channel.dropped,
        rate=0.0,
        new_problems=0,
        last_error=stats.last_error,
        flow=channel.flow.value if channel.flow is not None else "",
        why="\n".join(finding.text for finding in channel.findings),
        fault=any(finding.fault for finding in channel.findings),
        rate_limited=stats.rate_limited,
        errors_by_reason=_largest_first(dict(stats.errors_by_reason)),
        conversion_errors=stats.conversion_errors,
        native=channel.native,
        send_queue=channel.send_queue if isinstance(channel, RosToGzChannel) else 0,
    )


def service_status(service: ServiceBridge) -> ChannelStatus:
    """A service bridge: calls are "received", answered calls "published", failures errors,
    responses given up for a client never discovered "dropped"; calls still waiting for
    Gazebo are none of these yet. Without a Gazebo provider of its types it is "waiting for
    Gazebo", and says why (WARN when the providers take other types)."""
    why, fault = service.provider_problem()
    return ChannelStatus(
        flow=Flow.WAITING_GAZEBO.value if why else "",
        why=why,
        fault=fault,
        direction="service",
        ros_name=service.service_name,
        gz_name=service.spec.service,
        ros_type=service.spec.ros_type,
        gz_type=f"{service.gz_req_type}/{service.gz_rep_type}",
        state=ChannelState.ACTIVE.value,
        received=service.calls,
        published=service.calls - service.failures - service.unanswered - service.waiting,
        errors=service.failures,
        dropped=service.unanswered,
        rate=0.0,
        new_problems=0,
        last_error=service.last_failure,
        errors_by_reason=_largest_first(service.failures_by_reason),
        conversion_errors=service.failures_by_reason[NOT_CONVERTED],
    )


def _largest_first(counts: Mapping[str, int]) -> tuple[tuple[str, int], ...]:
    return tuple(sorted(counts.items(), key=lambda item: (-item[1], item[0])))


def diagnostic_array(statuses: list[ChannelStatus], hardware_id: str, stamp: Any) -> Any:
    """A ``DiagnosticArray`` with one ``DiagnosticStatus`` per channel."""
    array = DiagnosticArray()
    array.header.stamp = stamp
    for status in statuses:
        entry = DiagnosticStatus()
        entry.level = status.level
        entry.name = status.name
        entry.message = status.message()
        entry.hardware_id = hardware_id
        entry.values = [KeyValue(key=k, value=v) for k, v in status.values().items()]
        array.status.append(entry)
    return array


_COLUMNS = (
    ("LEVEL", lambda s: s.level_name),
    ("DIRECTION", lambda s: s.direction),
    ("ROS", lambda s: s.ros_name),
    ("GAZEBO", lambda s: s.gz_name),
    ("STATE", lambda s: s.state),
    ("IN", lambda s: str(s.received)),
    ("OUT", lambda s: str(s.published)),
    ("ERRORS", lambda s: str(s.errors)),
    ("DROPPED", lambda s: str(s.dropped)),
    ("LIMITED", lambda s: str(s.rate_limited)),
    ("RATE/s", lambda s: f"{s.rate:.1f}"),
    ("FLOW", lambda s: s.flow),
    ("PATH", lambda s: s.path),
)


def format_table(statuses: list[ChannelStatus]) -> str:
    """A plain-text table, one row per channel, columns padded to their widest cell."""
    rows = [[name for name, _ in _COLUMNS]]
    rows += [[cell(status) for _, cell in _COLUMNS] for status in statuses]
    widths = [max(len(row[i]) for row in rows) for i in range(len(_COLUMNS))]
    lines = [
        "  ".join(cell.ljust(width) for cell, width in zip(row, widths, strict=True)).rstrip()
        for row in rows
    ]
    if not statuses:
        lines.append("(no bridges)")
    # A cause of the whole bridge ("no Gazebo process heard") is one line, not one per channel.
    shared = collections.Counter(why for status in statuses for why in status.why.splitlines())
    said: set[str] = set()
    for status in statuses:
        for why in status.why.splitlines():
            if shared[why] == 1:
                lines.append(f"why {status.direction} {status.ros_name}: {why}")
            elif why not in said:
                said.add(why)
                lines.append(f"why {shared[why]} channels: {why}")
        if status.errors_by_reason:
            last = f"; last: {status.last_error}" if status.last_error else ""
            lines.append(
                f"errors {status.direction} {status.ros_name}: {status.error_summary()}{last}"
            )
    return "\n".join(lines)


class DiagnosticsPublisher:
    """Publishes the bridge's status on ``/diagnostics`` every ``period`` seconds (wall clock)."""

    def __init__(self, ros_node: Any, bridge: Bridge, period: float) -> None:
        self._node = ros_node
        self._tracker = StatusTracker(bridge)
        self._hardware_id = str(ros_node.get_fully_qualified_name())
        self._publisher = ros_node.create_publisher(DiagnosticArray, DIAGNOSTICS_TOPIC, 10)
        self._timer = ros_node.create_timer(period, self.publish, clock=steady_clock())

    def publish(self) -> None:
        stamp = self._node.get_clock().now().to_msg()
        self._publisher.publish(
            diagnostic_array(self._tracker.snapshot(), self._hardware_id, stamp)
        )

    def close(self) -> None:
        self._node.destroy_timer(self._timer)
        self._node.destroy_publisher(self._publisher)


@contextlib.contextmanager
def table_on_signal(
    bridge: Bridge, signum: int = signal.SIGUSR1, out: TextIO | None = None
) -> Iterator[None]:
    """While inside, signal ``signum`` prints the status table to ``out`` (stdout) once.

    The table is printed from a short-lived thread: a handler that wrote to stdout itself
    could interrupt the main thread in the middle of its own write.
    """
    tracker = StatusTracker(bridge)
    lock = threading.Lock()

    def print_table() -> None:
        with lock:  # two signals in quick succession: one whole table after the other
            table = format_table(tracker.snapshot())
            print(table, file=out if out is not None else sys.stdout, flush=True)

    def on_signal(_signum: int, _frame: FrameType | None) -> None:
        threading.Thread(target=print_table, name="status-table", daemon=True).start()

    previous = signal.signal(signum, on_signal)
    try:
        yield
    finally:
        signal.signal(signum, previous)


def serve(
    ros_node: Any,
    bridge: Bridge,
    stop: StopSignal,
    *,
    events_executor: bool,
    dds_event_batch: bool,
) -> None:
    """What both executables do once their bridges exist: spin ``ros_node`` until ``stop`` or
    rclpy shutdown, printing the status table on SIGUSR1 meanwhile. ``events_executor``: see
    :func:`~ros_gz_bridge_py.ros.runtime.make_executor`; ``dds_event_batch``:
    :func:`~ros_gz_bridge_py.ros.runtime.batch_dds_event_threads` first."""
    if dds_event_batch:
        batch_dds_event_threads()
    executor = make_executor(events=events_executor)
    executor.add_node(ros_node)
    with table_on_signal(bridge):
        spin_until_stopped(executor, stop)


def start_diagnostics(ros_node: Any, bridge: Bridge, period: object) -> DiagnosticsPublisher | None:
    """The publisher the ``status_period`` parameter asks for: None for 0 or a bad value.

    A bad value (not a number, negative) is logged; the bridge runs without status messages.
    """
    if isinstance(period, bool) or not isinstance(period, int | float) or period < 0:
        ros_node.get_logger().error(
            f"status_period must be a number of seconds >= 0 (0 = off), not {period!r}; "
            "not publishing /diagnostics"
        )
        return None
    if period == 0:
        return None
    return DiagnosticsPublisher(ros_node, bridge, float(period))

"""What the demo client measures and how it prints it: per-topic counters, the live table, the
final summary and its PASS/FAIL verdict. Plain text (one block per refresh) so the output reads
the same on a terminal and in a log file.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from ros_gz_bridge_py.demo.topics import BridgedTopic

#: Smallest pose change (m, rad) that counts as "the robot moved".
MOVED_DISTANCE = 0.01
MOVED_ANGLE = 0.01


@dataclass(frozen=True)
class Row:
    """One table line: a topic's rate (Hz), mean latency (ms; None without stamps), count."""

    topic: BridgedTopic
    rate_hz: float
    latency_ms: float | None
    count: int


@dataclass(frozen=True)
class Pose2D:
    x: float
    y: float
    yaw: float

    def differs_from(self, other: Pose2D) -> bool:
        turned = abs(math.remainder(self.yaw - other.yaw, math.tau))
        return math.hypot(self.x - other.x, self.y - other.y) > MOVED_DISTANCE or (
            turned > MOVED_ANGLE
        )

    def __str__(self) -> str:
        return f"x={self.x:+.3f} m  y={self.y:+.3f} m  yaw={math.degrees(self.yaw):+6.1f} deg"


class TopicStats:
    """Arrivals on one topic: totals since the start and a window since the last refresh."""

    def __init__(self, topic: BridgedTopic) -> None:
        self.topic = topic
        self.count = 0
        self._first: float | None = None
        self._last: float | None = None
        self._latency_sum = 0.0
        self._latency_samples = 0
        self._window_start: float | None = None
        self._window_count = 0
        self._window_latency_sum = 0.0
        self._window_latency_samples = 0

    def record(self, arrival: float, stamp: float | None) -> None:
        """One message that arrived at wall time ``arrival``, stamped ``stamp`` (seconds)."""
        self.count += 1
        self._window_count += 1
        if self._first is None:
            self._first = arrival
        self._last = arrival
        if stamp is not None:
            latency = arrival - stamp
            self._latency_sum += latency
            self._latency_samples += 1
            self._window_latency_sum += latency
            self._window_latency_samples += 1

    def window(self, now: float) -> Row:
        """Rate and latency since the previous call (or the first message); starts a new window."""
        start = self._window_start if self._window_start is not None else self._first
        span = now - start if start is not None else 0.0
        rate = self._window_count / span if span > 0 else 0.0
        row = Row(
            self.topic,
            rate,
            _mean_ms(self._window_latency_sum, self._window_latency_samples),
            self.count,
        )
        self._window_start = now
        self._window_count = 0
        self._window_latency_sum = 0.0
        self._window_latency_samples = 0
        return row

    def overall(self) -> Row:
        """Rate between the first and the last message, and the mean latency of all."""
        rate = 0.0
        if self._first is not None and self._last is not None and self._last > self._first:
            rate = (self.count - 1) / (self._last - self._first)
        return Row(self.topic, rate, _mean_ms(self._latency_sum, self._latency_samples), self.count)


def _mean_ms(total: float, samples: int) -> float | None:
    return 1000.0 * total / samples if samples else None


_HEADER = f"{'topic':<20} {'ROS type':<28} {'rate Hz':>8} {'latency ms':>10} {'count':>7}"


def format_rows(rows: list[Row]) -> list[str]:
    """The table: one line per topic under a header line (fits 80 columns)."""
    lines = [_HEADER]
    for row in rows:
        name = f"/{row.topic.name}"
        latency = "-" if row.latency_ms is None else f"{row.latency_ms:.1f}"
        lines.append(
            f"{name:<20} {row.topic.ros_type:<28} {row.rate_hz:>8.1f} {latency:>10} {row.count:>7}"
        )
    return lines


def format_pose(pose: Pose2D | None) -> str:
    return f"robot pose (odom): {pose if pose is not None else 'no odometry yet'}"


@dataclass(frozen=True)
class Verdict:
    passed: bool
    line: str


def verdict(rows: list[Row], first: Pose2D | None, last: Pose2D | None) -> Verdict:
    """PASS when every topic had messages at a non-zero rate and the robot moved."""
    silent = [f"/{row.topic.name}" for row in rows if row.count == 0 or row.rate_hz <= 0]
    moved = first is not None and last is not None and last.differs_from(first)
    problems = []
    if silent:
        problems.append(f"no traffic on {', '.join(silent)}")
    if not moved:
        problems.append("the robot did not move (cmd_vel ROS -> Gazebo, odom Gazebo -> ROS)")
    if problems:
        return Verdict(passed=False, line=f"FAIL: {'; '.join(problems)}")
    return Verdict(
        passed=True,
        line=(
            f"PASS: all {len(rows)} Gazebo -> ROS topics arrived at a non-zero rate and "
            "the robot moved under cmd_vel (ROS -> Gazebo)"
        ),
    )

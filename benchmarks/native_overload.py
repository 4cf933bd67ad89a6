"""Does a bridge keep delivering as the offered rate rises? Odometry Gazebo -> ROS at rising
rates through a fresh bridge on each path, to an rclpy subscriber that deserializes every
message and to one that takes them serialized (section 1 of ``benchmarks.native_plane``)."""

from __future__ import annotations

import itertools
import os
from collections.abc import Sequence
from dataclasses import dataclass

from benchmarks import plots
from benchmarks.bridged import bridge_process, flow_through
from benchmarks.harness import Flow, FlowResult, bridge_config, topic_name
from benchmarks.native_paths import (
    PATHS,
    SPLIT,
    Counters,
    MachineWindow,
    counted_since,
    counters,
    cpu_cell,
    path_backend,
    threads_cell,
)
from benchmarks.report import link
from benchmarks.small_messages import PACED_DEPTH
from benchmarks.tables import verdict

#: The ROS ends of the overload phase: whether each takes the messages serialized. "rclpy"
#: deserializes every message as an application does and so tops out at its own rate on these
#: cores; "serialized" reads only the stamp (rclpy's ``raw=True``), so what it misses is what
#: the bridge did not carry.
SUBSCRIBERS = {"rclpy": False, "serialized": True}
OVERLOAD_RATES = (1000.0, 2000.0, 5000.0, 10000.0, 20000.0, 40000.0)
#: The history depth of the ROS subscriber and the channel's queues in the overload phase.
QUEUE = PACED_DEPTH
#: Issue 22: the native path delivers at least this share at this offered rate...
GOAL_SHARE, GOAL_SHARE_HZ = 0.95, 20000.0
#: ...and its delivered rate never falls as the offered rate rises; a fall smaller than this
#: share of the best lower rate's is read as the run-to-run noise of 2 shared cores.
FALL_TOLERANCE = 0.05
#: Where the overload plot goes, relative to the repository root.
OVERLOAD_PNG = "benchmarks/plots/native_overload.png"


@dataclass(frozen=True)
class Point:
    """One offered rate through one path."""

    path: str
    hz: float
    seconds: float
    result: FlowResult
    counted: Counters | None
    #: The whole machine's CPU, % of all its cores, while publishing.
    machine: float | None = None
    #: The ROS end (a key of :data:`SUBSCRIBERS`).
    subscriber: str = "rclpy"

    @property
    def series(self) -> str:
        return f"{self.path} path, {self.subscriber} subscriber"

    @property
    def offered(self) -> float:
        """What the peer sent, per second."""
        return self.result.sent / self.seconds

    @property
    def delivered(self) -> float:
        """What the rclpy subscriber received, per second of publishing."""
        return self.result.received / self.seconds

    @property
    def published(self) -> float | None:
        """What the bridge published (its OUT counter), per second of publishing."""
        return None if self.counted is None else self.counted.published / self.seconds

    def cpu_per_message_us(self) -> float | None:
        if self.result.cpu is None or not self.result.received:
            return None
        return self.result.cpu / 100 / self.delivered * 1e6


def sweep(path: str, subscriber: str, seconds: float, rates: Sequence[float]) -> list[Point]:
    """Odometry at each of ``rates`` through one fresh bridge on ``path`` to ``subscriber``."""
    which = path_backend(path)
    topic = topic_name(f"native_overload_{path}_{subscriber}")
    arguments = bridge_config([(topic, "odometry", "gz2ros")], QUEUE)
    raw = SUBSCRIBERS[subscriber]
    points = []
    with bridge_process(arguments, which.bridge_env, channels=1) as bridge:
        for hz in rates:
            flow = Flow("gz-pub", "ros-sub", "odometry", seconds, hz, depth=QUEUE, raw=raw)
            before, machine = counters(bridge, [topic]), MachineWindow(seconds)
            result = flow_through(flow, topic, which, bridge, machine.begin)
            counted = counted_since(before, counters(bridge, [topic]), topic)
            points.append(Point(path, hz, seconds, result, counted, machine.percent, subscriber))
    return points


def point_row(point: Point) -> str:
    r = point.result
    what = f"| {point.path} | {point.subscriber} | {point.hz / 1000:g} kHz"
    if r.error:
        return f"{what} | failed: {r.error} |||||||||||||"
    per = point.cpu_per_message_us()
    counted = point.counted
    return (
        f"{what} | {point.offered / 1000:.1f} | {r.received}/{r.sent} "
        f"| **{point.delivered / 1000:.2f}** | {r.share:.1%} "
        f"| {'-' if point.published is None else f'{point.published / 1000:.2f}'} "
        f"| {'-' if counted is None else counted.text()} "
        f"| {'-' if counted is None else counted.path} | {cpu_cell(r.cpu)} "
        f"| {'-' if per is None else f'{per:.0f}'} | {threads_cell(r.bridge_threads)} "
        f"| {cpu_cell(r.sub_cpu)} | {cpu_cell(point.machine)} | {r.median_us / 1000:.2f} "
        f"| {r.p99_us / 1000:.2f} |"
    )


OVERLOAD_HEADER = (
    "| path | ROS subscriber | offered | sent, kHz | delivered/sent | delivered, kHz | share "
    "| bridge published, kHz | bridge in / out / dropped | PATH column | bridge CPU "
    f"| bridge CPU per delivered message, µs | of which {SPLIT} threads "
    "| subscriber CPU | machine CPU | median ms | p99 ms |\n"
    "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"
)


def falls(points: Sequence[Point]) -> list[str]:
    """Where the delivered rate fell (beyond :data:`FALL_TOLERANCE`) below that of a lower
    offered rate."""
    found, best, best_hz = [], 0.0, 0.0
    for point in sorted(points, key=lambda p: p.hz):
        if point.result.error:
            continue
        if point.delivered < best * (1 - FALL_TOLERANCE):
            found.append(
                f"{point.delivered / 1000:.2f} kHz at {point.hz / 1000:g} kHz offered against "
                f"{best / 1000:.2f} kHz at {best_hz / 1000:g} kHz"
            )
        if point.delivered > best:
            best, best_hz = point.delivered, point.hz
    return found


def where_lost(point: Point) -> str:
    """What bounds a point that lost messages: the bridge (its counters) or its subscriber."""
    r, counted = point.result, point.counted
    if counted is None or r.error:
        return ""
    bridge_lost = r.sent - counted.published
    after_bridge = counted.published - r.received
    text = (
        f"of {r.sent} sent the bridge published {counted.published} (it dropped "
        f"{counted.dropped} in its queue; {max(bridge_lost - counted.dropped, 0)} never reached "
        f"it) and the {point.subscriber} subscriber took {r.received} of those "
        f"({r.received / max(counted.published, 1):.1%}), itself busy {cpu_cell(r.sub_cpu)} of a "
        f"core; the bridge {cpu_cell(r.cpu)} ({SPLIT} threads: {threads_cell(r.bridge_threads)}); "
        f"the machine's {os.cpu_count()} cores {cpu_cell(point.machine)} busy"
    )
    if after_bridge > bridge_lost:
        text += (
            ": most were lost after the bridge, between its reliable keep-last "
            f"{QUEUE} writer and a subscriber that takes fewer a second than it is sent"
        )
    return text


def overload_goals(points: list[Point]) -> list[str]:
    lines = []
    for subscriber in SUBSCRIBERS:
        native = {p.hz: p for p in points if p.path == "native" and p.subscriber == subscriber}
        what = (
            f"- Native delivers >= {GOAL_SHARE:.0%} at {GOAL_SHARE_HZ / 1000:g} kHz to the "
            f"{subscriber} subscriber"
        )
        at = native.get(GOAL_SHARE_HZ)
        if at is None or at.result.error:
            lines.append(f"{what}: not measured")
            continue
        share = at.result.share
        gap = f"{(GOAL_SHARE - share) * 100:.1f} percentage points"
        bound = "" if share >= GOAL_SHARE else f"; {where_lost(at)}"
        lines.append(
            f"{what}: {at.result.received}/{at.result.sent} = {share:.1%} — "
            f"{verdict(share >= GOAL_SHARE, gap)}{bound}"
        )
    for path, subscriber in itertools.product(PATHS, SUBSCRIBERS):
        mine = sorted(
            (p for p in points if p.path == path and p.subscriber == subscriber),
            key=lambda p: p.hz,
        )
        if not mine:
            continue
        fell = falls(mine)
        rates = ", ".join(f"{p.delivered / 1000:.2f}" for p in mine)
        what = "the goal" if path == "native" else "for comparison"
        published = [p.published for p in mine]
        rising = all(
            (later or 0) >= (earlier or 0) * (1 - FALL_TOLERANCE)
            for earlier, later in itertools.pairwise(published)
        )
        lines.append(
            f"- {mine[0].series}: the delivered rate never falls as the offered rate rises "
            f"({what}; falls within {FALL_TOLERANCE:.0%} count as noise): {rates} kHz — "
            f"{verdict(not fell, '; '.join(fell))}. What the bridge itself published: "
            + ", ".join("-" if rate is None else f"{rate / 1000:.2f}" for rate in published)
            + f" kHz ({'never falls' if rising else 'falls'})"
        )
    return lines


def plot(points: list[Point]) -> str:
    names = dict.fromkeys(p.series for p in points)
    series = {
        f"{name}, delivered": [
            (p.hz / 1000, p.delivered / 1000) for p in points if p.series == name
        ]
        for name in names
    }
    series |= {  # what the bridge published does not depend on the subscriber: one line a path
        f"{path} path, published by the bridge ({subscriber} subscriber)": [
            (p.hz / 1000, p.published / 1000)
            for p in points
            if p.path == path and p.subscriber == subscriber and p.published is not None
        ]
        for path, subscriber in ((path, list(SUBSCRIBERS)[-1]) for path in PATHS)
    }
    try:
        drawn = plots.native_overload_plot(series, OVERLOAD_PNG)
    except ImportError:
        return "Plot not drawn: matplotlib is missing (`make bench` installs `.[bench]`)."
    return f"![Odometry Gazebo -> ROS: delivered against offered, native and Python]({link(drawn)})"

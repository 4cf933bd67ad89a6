"""Does /clock get through while Odometry floods the same Gazebo process and the same bridge?
/clock at 1 kHz to a depth-10 subscriber beside a 40 kHz Odometry stream, on each path (section 3
of ``benchmarks.native_plane``)."""

from __future__ import annotations

import os
from dataclasses import dataclass

from benchmarks.bridged import bridge_process, flow_through
from benchmarks.harness import Flood, Flow, FlowResult, bridge_argument, topic_name
from benchmarks.native_paths import (
    SPLIT,
    Counters,
    MachineWindow,
    counted_since,
    counters,
    cpu_cell,
    path_backend,
    threads_cell,
)
from benchmarks.reference import GOAL_CLOCK_SHARE
from benchmarks.tables import verdict

CLOCK_HZ = 1000.0
#: The Odometry stream beside /clock, and how long it runs before the first clock message.
FLOOD_HZ, FLOOD_LEAD = 40000.0, 2.0


@dataclass(frozen=True)
class ClockRun:
    path: str
    result: FlowResult
    clock: Counters | None
    flood: Counters | None
    machine: float | None = None


def clock_under_flood(path: str, seconds: float) -> ClockRun:
    """/clock at 1 kHz to a default (depth 10) subscriber while the same Gazebo process
    sends Odometry at :data:`FLOOD_HZ` through the same bridge on ``path``."""
    which = path_backend(path)
    clock, odometry = topic_name(f"native_clock_{path}"), topic_name(f"native_flood_{path}")
    arguments = [
        bridge_argument(clock, "clock", "gz2ros"),
        bridge_argument(odometry, "odometry", "gz2ros"),
    ]
    flood = Flood("odometry", odometry, hz=FLOOD_HZ, lead=FLOOD_LEAD)
    flow = Flow("gz-pub", "ros-sub", "clock", seconds, CLOCK_HZ, flood=flood)
    with bridge_process(arguments, which.bridge_env) as bridge:
        before, machine = counters(bridge, [clock, odometry]), MachineWindow(seconds)
        result = flow_through(flow, clock, which, bridge, machine.begin)
        after = counters(bridge, [clock, odometry])
    return ClockRun(
        path, result, counted_since(before, after, clock), counted_since(before, after, odometry),
        machine.percent,
    )  # fmt: skip


def clock_row(run: ClockRun) -> str:
    r = run.result
    if r.error:
        return f"| {run.path} | failed: {r.error} |||||||||||"
    flood = "-" if r.flood is None else f"{r.flood.received}/{r.flood.sent}"
    paths = " / ".join(c.path if c else "-" for c in (run.clock, run.flood))
    return (
        f"| {run.path} | {r.received}/{r.sent} | **{r.share:.1%}** | {r.median_us / 1000:.2f} "
        f"| {r.p99_us / 1000:.2f} | {run.clock.text() if run.clock else '-'} | {flood} "
        f"| {run.flood.text() if run.flood else '-'} | {paths} | {cpu_cell(r.cpu)} "
        f"| {threads_cell(r.bridge_threads)} | {cpu_cell(r.sub_cpu)} | {cpu_cell(run.machine)} |"
    )


CLOCK_HEADER = (
    "| path | /clock delivered/sent | share | median ms | p99 ms | /clock channel in / out / "
    "dropped | Odometry delivered/sent | Odometry channel in / out / dropped | PATH column "
    f"(clock / Odometry) | bridge CPU | of which {SPLIT} threads | /clock subscriber CPU "
    "| machine CPU |\n|---|---|---|---|---|---|---|---|---|---|---|---|---|"
)


def clock_goal(runs: list[ClockRun]) -> str:
    native = next((run for run in runs if run.path == "native"), None)
    what = f"- /clock >= {GOAL_CLOCK_SHARE:.0%} under the Odometry flood, native"
    if native is None or native.result.error:
        return f"{what}: not measured"
    r = native.result
    python = next((run.result for run in runs if run.path == "Python"), None)
    beside = "" if python is None or python.error else f" (the Python path: {python.share:.1%})"
    met = r.share >= GOAL_CLOCK_SHARE
    line = (
        f"{what}: {r.received}/{r.sent} = {r.share:.1%}{beside} — "
        f"{verdict(met, f'{(GOAL_CLOCK_SHARE - r.share) * 100:.1f} percentage points')}"
    )
    if not met and native.clock is not None:
        line += (
            f"; the clock channel received {native.clock.received}, published "
            f"{native.clock.published}, dropped {native.clock.dropped}, and its depth-10 "
            f"subscriber took {r.received} of those (p99 latency {r.p99_us / 1000:.1f} ms); "
            f"the bridge {cpu_cell(r.cpu)} ({SPLIT}: {threads_cell(r.bridge_threads)}), the "
            f"machine's {os.cpu_count()} cores {cpu_cell(native.machine)} busy"
        )
    return line

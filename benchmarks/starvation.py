"""``/clock`` at 1 kHz while 1080p frames flood the same Gazebo process flat out (issues 3, 15).

Usage: ``.venv/bin/python -m benchmarks.starvation [--seconds S]``; writes the report
``benchmarks/reports/starvation.md`` and stores its flows for the headline. One Gazebo
publisher process sends ``gz.msgs.Clock`` at 1 kHz and, from another thread of the same
process, 1920x1080 images back to back (``kind-pub --flood``), as a simulator sends its clock
beside a camera. Goal (issue 15): >= 99% of the clock messages reach the default subscriber.
"""

from __future__ import annotations

import argparse
import os
import sys
from dataclasses import dataclass

from benchmarks.bridged import Backend, backend, bridge_process, flow_through
from benchmarks.harness import (
    GZ_ENDS,
    Flood,
    Flow,
    FlowResult,
    bridge_argument,
    run_flow,
    topic_name,
)
from benchmarks.native_paths import Counters, counted_since, counters
from benchmarks.reference import CLOCK_UNDER_FLOOD, GOAL_CLOCK_SHARE, QUOTED
from benchmarks.report import write_section
from benchmarks.results import store
from benchmarks.tables import verdict
from benchmarks.transport import LARGE_HWM
from testing.gzpeer import PeerProcess
from testing.run_env import run_env

CLOCK_HZ = 1000.0
#: Seconds the flood runs before the first clock message.
LEAD = 3.0
#: History depth of the deep subscriber: room for a 100 ms burst at 1 kHz.
DEEP_DEPTH = 100


HEADER = (
    "| /clock | received/sent | received | median ms | p99 ms | bridge in / out / dropped "
    "| flood frames delivered/sent | bridge CPU |\n|---|---|---|---|---|---|---|---|"
)


@dataclass(frozen=True)
class Phase:
    """One clock measurement: its stored name, its row label and its ROS subscriber."""

    name: str
    label: str
    depth: int | None = None
    qos_profile: str | None = None


ALONE = Phase("alone", "/clock alone, subscriber depth 10")
DEFAULT = Phase("flood", "**under the flood, subscriber depth 10 (the bridge's default QoS)**")
DEEP = Phase("deep", f"under the flood, subscriber depth {DEEP_DEPTH}", DEEP_DEPTH)
CLOCK_QOS = Phase(
    "clock_qos",
    "under the flood, a /clock subscription as rclcpp and rclpy make one for use_sim_time "
    "(best effort, keep last 1)",
    qos_profile="CLOCK",
)
BYPASS = Phase("bypass", "control: the flood bypasses the bridge (to a Gazebo subscriber)")
HOP = Phase("hop", "Gazebo hop alone: a Gazebo subscriber of /clock, no bridge, no ROS")
CEILING = Phase("ceiling", "ceiling: rclpy publisher of /clock and of the flood -> rclpy")
SAME_FLOOD = Phase(
    "same_flood",
    "ceiling under the same flood: rclpy publisher of /clock -> rclpy, a Gazebo process "
    "flooding frames to a Gazebo subscriber",
)
PHASES = (ALONE, DEFAULT, DEEP, CLOCK_QOS, BYPASS, HOP, CEILING, SAME_FLOOD)
#: Phases a stored run may lack (it predates them): the notes leave their line out.
LATER_PHASES = frozenset({SAME_FLOOD.name})


@dataclass(frozen=True)
class ClockRun:
    """One phase's flow, and what the bridge's clock channel counted meanwhile."""

    phase: Phase
    result: FlowResult
    #: The bridge's IN, OUT and DROPPED counters of the clock channel over the flow.
    counted: Counters | None = None


def _counted(
    phase: Phase, flow: Flow, topic: str, which: Backend, bridge: PeerProcess | None
) -> ClockRun:
    first = counters(bridge, [topic])
    result = flow_through(flow, topic, which, bridge)
    return ClockRun(phase, result, counted_since(first, counters(bridge, [topic]), topic))


def _flow(phase: Phase, ends: tuple[str, str], seconds: float, flood: Flood | None) -> Flow:
    return Flow(
        *ends, "clock", seconds, CLOCK_HZ, depth=phase.depth, qos_profile=phase.qos_profile,
        flood=flood,
    )  # fmt: skip


def bridged(seconds: float) -> list[ClockRun]:
    """The phases through a bridge: one with a clock and an image channel, then a control
    bridge with the clock channel only, the flood going to a Gazebo subscriber."""
    which = backend("zeromq")
    clock, image = topic_name("clock"), topic_name("clock_flood")
    flood = Flood("image1080", image, lead=LEAD)
    arguments = [
        bridge_argument(clock, "clock", "gz2ros"),
        bridge_argument(image, "image1080", "gz2ros"),
    ]
    ends = ("gz-pub", "ros-sub")
    with bridge_process(arguments, which.bridge_env) as bridge:
        runs = [_counted(ALONE, _flow(ALONE, ends, seconds, None), clock, which, bridge)]
        for phase in (DEFAULT, DEEP, CLOCK_QOS):
            runs.append(_counted(phase, _flow(phase, ends, seconds, flood), clock, which, bridge))
    clock = topic_name("clock_control")
    bypass = Flood("image1080", topic_name("clock_bypass"), lead=LEAD, bypass=True)
    with bridge_process([bridge_argument(clock, "clock", "gz2ros")], which.bridge_env) as bridge:
        runs.append(_counted(BYPASS, _flow(BYPASS, ends, seconds, bypass), clock, which, bridge))
    return runs


def unbridged(seconds: float) -> list[ClockRun]:
    """The Gazebo hop alone and the rclpy ceiling, each under its own same-process flood, and
    the rclpy ceiling beside a Gazebo process flooding as the bridged rows' publisher does."""
    runs = []
    for phase, ends in (
        (HOP, ("gz-pub", "gz-sub")),
        (CEILING, ("ros-pub", "ros-sub")),
        (SAME_FLOOD, ("ros-pub", "ros-sub")),
    ):
        apart = phase is SAME_FLOOD
        flood = Flood("image1080", topic_name(f"{phase.name}_flood"), lead=LEAD, apart=apart)
        flow = _flow(phase, ends, seconds, flood)
        result = run_flow(flow, topic_name(f"{phase.name}_clock"), run_env())
        print(f"{phase.name}: {result}", file=sys.stderr, flush=True)
        runs.append(ClockRun(phase, result))
    return runs


def _row(run: ClockRun) -> str:
    r = run.result
    if r.error:
        return f"| {run.phase.label} | failed: {r.error} |||||||"
    counted = "-" if run.counted is None else run.counted.text()
    flood = "-" if r.flood is None else f"{r.flood.received}/{r.flood.sent}"
    cpu = "-" if r.cpu is None else f"{r.cpu:.0f}%"
    return (
        f"| {run.phase.label} | {r.received}/{r.sent} | {r.share:.1%} | "
        f"{r.median_us / 1000:.2f} | {r.p99_us / 1000:.2f} | {counted} | {flood} | {cpu} |"
    )


def bounds(runs: dict[str, ClockRun]) -> list[str]:
    """Where this run's clock messages were lost, from the measured phases."""
    lines = []
    default = runs[DEFAULT.name]
    result = default.result
    counted = default.counted
    if counted is not None and result.sent:
        received, published, dropped = counted.received, counted.published, counted.dropped
        took = result.received / max(published, 1)
        lines.append(
            f"- Of the {result.sent} clock messages sent under the flood, the bridge received "
            f"{received} ({received / result.sent:.1%}; {result.sent - received} "
            "never reached its queue: the Gazebo publisher drops what exceeds its send queue of "
            f"{LARGE_HWM} messages, set so (GZ_TRANSPORT_SNDHWM) for the whole flooding process "
            "to bound its queue of 6 MB frames, where Gazebo's default is 1000), dropped "
            f"{dropped} in its own queue and published {published}; the "
            f"subscriber took {result.received} of those ({took:.1%})."
        )
    hop = runs[HOP.name].result
    if not hop.error:
        lines.append(
            f"- The flooded publisher's own delivery: a Gazebo subscriber fed straight by it "
            f"received {hop.share:.1%}, p99 latency {hop.p99_us / 1000:.1f} ms (median "
            f"{hop.median_us / 1000:.2f} ms); a clock message that waits that long arrives "
            "with those sent after it, in a burst."
        )
    bypass = runs[BYPASS.name].result
    if not bypass.error and not result.error:
        lines.append(
            f"- With the flood bypassing the bridge (the bridge {bypass.cpu or 0:.0f}% of a "
            f"core, its clock channel alone; the frames to a Gazebo subscriber instead of an "
            f"rclpy one), the depth-10 subscriber received {bypass.share:.1%}, "
            f"{(bypass.share - result.share) * 100:+.1f} points against the flood through the "
            "bridge: what carrying the frames (the bridge's image channel and the rclpy "
            "subscriber of the frames, on the same 2 cores) costs the clock."
        )
    if counted is not None and result.sent and not bypass.error and not result.error:
        lines.append(_shares(result, counted, bypass))
    deep, ceiling = runs[DEEP.name].result, runs[CEILING.name].result
    if not deep.error:
        lines.append(
            f"- A subscriber of depth {DEEP_DEPTH} received {deep.share:.1%} (p99 "
            f"{deep.p99_us / 1000:.1f} ms): a keep-last history loses the oldest of a burst "
            "that outgrows it before the subscriber's process is back on the CPU."
        )
    if not ceiling.error:
        frames = "no" if ceiling.flood is None else f"{ceiling.flood.received}"
        lines.append(
            f"- rclpy alone (its own flood, which DDS flow control slows to what the frames' "
            f"subscriber takes: {frames} frames delivered) gave a depth-10 subscriber "
            f"{ceiling.share:.1%}."
        )
    same = runs.get(SAME_FLOOD.name)
    if same is not None and not same.result.error and not result.error:
        lines.append(_same_flood(same.result, result, bypass, hop))
    return lines


def _same_flood(same: FlowResult, result: FlowResult, bypass: FlowResult, hop: FlowResult) -> str:
    """The same run's yardstick: rclpy's own /clock beside the flooding Gazebo process, and
    what it says of where the bridged rows lose theirs."""
    frames = "-" if same.flood is None else f"{same.flood.received}/{same.flood.sent}"
    control = "" if bypass.error else f", the control row {(bypass.share - same.share) * 100:+.1f}"
    if same.share < GOAL_CLOCK_SHARE:
        why = "the machine under this flood leaves even rclpy short of the goal"
    elif hop.error:
        why = "the subscriber keeps up with a steady 1 kHz under this load"
    else:
        why = (
            "the subscriber keeps up with a steady 1 kHz under this load; the bridge's clock "
            "comes in the bursts in which the flooding process sends it (the hop's p99: "
            f"{hop.p99_us / 1000:.0f} ms), published as they come, and a burst that outgrows "
            "the depth-10 history before the subscriber drains it loses its oldest"
        )
    return (
        "- The same run's yardstick: rclpy alone publishing /clock at 1 kHz to the same depth-10 "
        "subscriber, beside a Gazebo process flooding 1080p frames back to back to a Gazebo "
        f"subscriber ({frames} frames delivered), gave {same.share:.1%} (p99 "
        f"{same.p99_us / 1000:.1f} ms): the bridge under the flood "
        f"{(result.share - same.share) * 100:+.1f} points against it{control}; {why}."
    )


def _shares(result: FlowResult, counted: Counters, bypass: FlowResult) -> str:
    """Which part of the loss under the flood the bridge can change, and which it cannot."""
    before = result.sent - counted.received
    after = counted.published - result.received
    return (
        f"- What the bridge can change, and what it cannot: of the {result.sent - result.received} "
        f"clock messages lost under the flood, {counted.dropped} were dropped in the bridge's "
        f"own queue (its part: the queue, and the CPU it leaves the subscriber); {before} were "
        "lost before it, in the flooded Gazebo process's send queue, and "
        f"{after} after it, between its ROS writer and the subscriber, whose keep-last history "
        "only the subscriber's process empties: with the bridge at "
        f"{bypass.cpu or 0:.0f}% of a core and its clock channel alone (the control row), the "
        f"same subscriber still lost {1 - bypass.share:.1%}."
    )


def _yardstick(runs: dict[str, ClockRun]) -> str:
    same = runs[SAME_FLOOD.name].result
    if same.error:
        return ""
    return f"The same run's rclpy ceiling under the same flood: {same.share:.1%}. "


def run(seconds: float) -> tuple[str, dict[str, ClockRun]]:
    runs = {run.phase.name: run for run in bridged(seconds) + unbridged(seconds)}
    default, alone = runs[DEFAULT.name].result, runs[ALONE.name].result
    met = default.share >= GOAL_CLOCK_SHARE and not default.error
    gap = f"{(GOAL_CLOCK_SHARE - default.share) * 100:.1f} percentage points"
    table = "\n".join(_row(run) for run in runs.values())
    return (
        f"""## /clock while 1080p frames flood the same Gazebo process (issues 3, 15)

Command: `.venv/bin/python -m benchmarks.starvation --seconds {seconds:g}`

One Gazebo publisher process sends `/clock` (gz.msgs.Clock at {CLOCK_HZ:g} Hz, `sim` =
CLOCK_MONOTONIC) and, from another thread of the same process, 1920x1080 rgb8 images back to
back, from {LEAD:g} s before the first clock message until after the last (the C++ peer's
`kind-pub --flood`: one ign-transport process, so clock and frames share its ZeroMQ sockets and
I/O thread, as in a simulator; its send queue is 20 messages, as every large-message flow of
these benchmarks). One parameter_bridge carries both topics, Gazebo -> ROS, each to an rclpy
subscriber ({seconds:g} s of clock per row). "Bridge in / out / dropped" is the clock
channel's own counters (SIGUSR1 status table) over the row. The control row uses a second
bridge with the clock channel only, the flood going from the same publisher to a Gazebo
subscriber; the last three rows have no bridge: Gazebo subscribers of both topics, rclpy
publishing both from one process (the ceiling), and rclpy publishing /clock beside a Gazebo
process that floods as the bridged rows' publisher does (the ceiling under the same flood).
Bridge CPU: % of one core. {GZ_ENDS}

{HEADER}
{table}

Goal (issue 15: >= {GOAL_CLOCK_SHARE:.0%} of /clock while 1080p frames flood the same Gazebo
process): {default.received}/{default.sent} = {default.share:.1%} arrived at the default
subscriber, latency median {default.median_us / 1000:.2f} ms, p99 {default.p99_us / 1000:.2f} ms
(alone: {alone.share:.1%}, p99 {alone.p99_us / 1000:.2f} ms) — {verdict(met, gap)}.
{_yardstick(runs)}The C++ bridge: {CLOCK_UNDER_FLOOD.cpp_text()} ({QUOTED}).

Where the clock messages were lost in this run, and what bounds the figure:
{chr(10).join(bounds(runs))}
""",
        runs,
    )


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--seconds", type=float, default=5.0, help="clock publishing time")
    args = parser.parse_args(argv)
    load = os.getloadavg()[0]
    section, runs = run(args.seconds)
    write_section("starvation", section)
    numbers: dict[str, float] = {}
    for name, clock_run in runs.items():
        if clock_run.counted is not None:
            numbers |= clock_run.counted.numbers(f"{name} bridge ")
    store("starvation", {name: r.result for name, r in runs.items()}, load, numbers)
    return 0


if __name__ == "__main__":
    sys.exit(main())

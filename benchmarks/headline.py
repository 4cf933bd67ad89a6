"""The headline of BENCHMARKS.md: issue 15's figures at a glance, the fleet of issues 28 and 36,
and the plots.

Usage: ``.venv/bin/python -m benchmarks.headline`` (``benchmarks.run`` calls it last). It
reads what ``sustained``, ``costs``, ``starvation``, ``fleet`` and ``busy_neighbour`` stored
in ``benchmarks/results.json``, writes the headline at the top of BENCHMARKS.md and draws the
plots it links. Each figure is shown with the commit and date of the run it came from, and each
verdict is computed from the figure beside it when the headline is written, never stored.
"""

from __future__ import annotations

import sys

from benchmarks import busy_neighbour, plots, starvation
from benchmarks.costs import (
    GZ_TO_ROS,
    ROS_TO_GZ,
    SPLIT_COLUMN,
    SPLIT_GROUPS,
    flow_key,
    per_message_ms,
    split_text,
    thread_split_ms,
)
from benchmarks.fleet_goals import (
    CPP_CEILING_RATIO,
    GOAL_CLOCK,
    GOAL_CLOCK_ROBOTS,
    GOAL_DELIVERED,
    GOAL_DELIVERED_ROBOTS,
    GOAL_IDLE_PERCENT,
    GOAL_RATIO,
    KINDS,
    idle_ceiling_text,
    short_kinds,
)
from benchmarks.harness import PYTHON_THREADS, FlowResult
from benchmarks.native_paths import stored_counters
from benchmarks.reference import (
    CLOCK_UNDER_FLOOD,
    CPU_PER_FRAME_30HZ,
    CPU_PER_MESSAGE,
    GOAL_CLOCK_SHARE,
    GOAL_CPU_PER_FRAME_30HZ_MS,
    GOAL_LATENCY_30HZ_MS,
    GOAL_SUSTAINED_HZ,
    LATENCY_30HZ,
    SUSTAINED_1080P,
    cpu_goal_ms,
)
from benchmarks.report import write_section
from benchmarks.results import Stored, load
from benchmarks.sustained import PACED_HZ, highest, side_flows
from benchmarks.tables import SIZES, verdict

HEADER = (
    "| figure | this bridge | ceiling, same run | goal (issue 15), verdict from this row's figure "
    "| C++ ros_gz_bridge, not measured here (issue 15's run) | measured at |\n"
    "|---|---|---|---|---|---|"
)
CASES = [("GZ->ROS", kind, hz) for kind, hz in GZ_TO_ROS]
CASES += [("ROS->GZ", kind, hz) for kind, hz in ROS_TO_GZ]


def _ms(value: float | None) -> str:
    return "-" if value is None else f"{value:.3f}"


def _latency(flow: FlowResult) -> str:
    return f"{flow.median_us / 1000:.1f} ms (p99 {flow.p99_us / 1000:.1f} ms)"


def _rate(hz: float | None, offered: list[float]) -> str:
    if hz is None:
        return f"below {min(offered):g} Hz"
    return f"{hz:g} Hz" + (" (the highest offered)" if hz == max(offered) else "")


def image_rows(stored: Stored | None) -> list[str]:
    """Highest sustainable 1080p rate; latency and CPU per frame at 30 Hz."""
    if stored is None:
        return ["| 1080p Gazebo -> ROS | not measured yet (`benchmarks.sustained`) |||||"]
    bridge, ceiling = side_flows(stored, "bridge"), side_flows(stored, "ceiling")
    best, offered = highest(bridge), sorted(bridge)
    met = best is not None and best >= GOAL_SUSTAINED_HZ
    rows = [
        "| Highest sustainable 1080p rate, Gazebo -> ROS (>= 99% delivered, p99 < 100 ms) "
        f"| **{_rate(best, offered)}** | {_rate(highest(ceiling), offered)} "
        f"| >= {GOAL_SUSTAINED_HZ:g} Hz: {verdict(met, f'{GOAL_SUSTAINED_HZ - (best or 0):g} Hz')}"
        f" | {SUSTAINED_1080P.cpp_text()} | {stored.measured()} |"
    ]
    paced, base = bridge.get(PACED_HZ), ceiling.get(PACED_HZ)
    if paced is None or paced.error:
        return rows
    median = paced.median_us / 1000
    late = f"{median - GOAL_LATENCY_30HZ_MS:.2f} ms"
    rows.append(
        f"| 1080p Gazebo -> ROS at {PACED_HZ:g} Hz, latency median | **{_latency(paced)}** "
        f"| {'-' if base is None or base.error else _latency(base)} "
        f"| <= {GOAL_LATENCY_30HZ_MS:g} ms: {verdict(median <= GOAL_LATENCY_30HZ_MS, late)} "
        f"| {LATENCY_30HZ.cpp_text()} | {stored.measured()} |"
    )
    frame = per_message_ms(paced.cpu, PACED_HZ, paced)
    if frame is not None:
        over = f"{frame - GOAL_CPU_PER_FRAME_30HZ_MS:.2f} ms"
        split = thread_split_ms(PACED_HZ, paced)
        of_which = ""
        if split is not None:
            of_which = f" ({' / '.join(SPLIT_GROUPS)} threads: {split_text(split)})"
        rows.append(
            f"| 1080p Gazebo -> ROS at {PACED_HZ:g} Hz, bridge CPU per frame "
            f"| **{frame:.2f} ms**{of_which} | {_frame_ends(base)} "
            f"| <= {GOAL_CPU_PER_FRAME_30HZ_MS:g} ms: "
            f"{verdict(frame <= GOAL_CPU_PER_FRAME_30HZ_MS, over)} "
            f"| {CPU_PER_FRAME_30HZ.cpp_text()} | {stored.measured()} |"
        )
    return rows


def _frame_ends(ceiling: FlowResult | None) -> str:
    """The rclpy ends' CPU per frame in the ceiling flow at the paced rate."""
    publisher, subscriber = _ends_of(ceiling, PACED_HZ)
    if publisher is None or subscriber is None:
        return "-"
    return f"rclpy publisher {publisher:.2f} ms, subscriber {subscriber:.2f} ms"


def clock_row(stored: Stored | None) -> str:
    what = "/clock at 1 kHz received while 1080p frames flood the same Gazebo process"
    default = None if stored is None else stored.flow(starvation.DEFAULT.name)
    if stored is None or default is None or default.error:
        return f"| {what} | not measured yet (`benchmarks.starvation`) |||||"
    ceiling = stored.flow(starvation.CEILING.name)
    same = stored.flow(starvation.SAME_FLOOD.name)
    ceilings = "-" if ceiling is None else f"{ceiling.share:.1%}"
    if same is not None and not same.error:
        ceilings += f"; {same.share:.1%} beside the same Gazebo flood"
    gap = f"{(GOAL_CLOCK_SHARE - default.share) * 100:.1f} points"
    return (
        f"| {what} (depth-10 subscriber) | **{default.share:.1%}**, latency "
        f"{_latency(default)} | {ceilings} "
        f"| >= {GOAL_CLOCK_SHARE:.0%}: {verdict(default.share >= GOAL_CLOCK_SHARE, gap)} "
        f"| {CLOCK_UNDER_FLOOD.cpp_text()} | {stored.measured()} |"
    )


def _ends(stored: Stored, kind: str, hz: float) -> tuple[float | None, float | None]:
    """CPU per message of the rclpy publisher and subscriber at the same rate (ms)."""
    return _ends_of(stored.flow(flow_key("ceiling", kind, hz)), hz)


def _ends_of(ceiling: FlowResult | None, hz: float) -> tuple[float | None, float | None]:
    """CPU per message (ms) of a ceiling flow's rclpy publisher and subscriber."""
    if ceiling is None:
        return None, None
    return (
        per_message_ms(ceiling.pub_cpu, hz, ceiling),
        per_message_ms(ceiling.sub_cpu, hz, ceiling),
    )


def cpu_rows(stored: Stored | None) -> list[str]:
    """The issue's three CPU-per-message goals."""
    rows = []
    for (kind, way, hz), quoted in CPU_PER_MESSAGE.items():
        what = f"CPU per message, {SIZES[kind]} {way} at {hz / 1000:g} kHz"
        flow = None if stored is None else stored.flow(flow_key(way, kind, hz))
        cost = None if flow is None else per_message_ms(flow.cpu, hz, flow)
        if stored is None or flow is None or cost is None:
            rows.append(f"| {what} | not measured yet (`benchmarks.costs`) |||||")
            continue
        publisher, subscriber = _ends(stored, kind, hz)
        end = f"rclpy publisher {_ms(publisher)} ms, subscriber {_ms(subscriber)} ms"
        bar = cpu_goal_ms(quoted)
        misses = [f"{cost - bar:.3f} ms ({cost / bar:.1f}x)"] if cost > bar else []
        if flow.received < flow.sent:
            misses.append(f"{flow.sent - flow.received} messages not delivered")
        rows.append(
            f"| {what}, every message delivered | **{cost:.3f} ms** "
            f"({flow.received}/{flow.sent} delivered) | {end} "
            f"| <= {bar:.3f} ms: {verdict(not misses, ' and '.join(misses))} "
            f"| {quoted.cpp_text()} | {stored.measured()} |"
        )
    return rows


def per_type(stored: Stored | None) -> str:
    """CPU per delivered message of every type, direction and rate measured."""
    if stored is None:
        return "Not measured yet (`benchmarks.costs`)."
    lines = [
        f"| message | direction | rate | bridge, ms per message | {SPLIT_COLUMN} "
        "| rclpy publisher, ms | rclpy subscriber, ms | delivered/sent |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for way, kind, hz in CASES:
        flow = stored.flow(flow_key(way, kind, hz))
        if flow is None:
            continue
        publisher, subscriber = _ends(stored, kind, hz)
        lines.append(
            f"| {SIZES[kind]} | {way} | {hz / 1000:g} kHz "
            f"| **{_ms(per_message_ms(flow.cpu, hz, flow))}** "
            f"| {split_text(thread_split_ms(hz, flow))} | {_ms(publisher)} "
            f"| {_ms(subscriber)} | {flow.received}/{flow.sent} |"
        )
    return "\n".join(lines)


def cpu_notes(stored: Stored | None) -> list[str]:
    """For each CPU-per-message goal missed: the bridge's cost beside the rclpy ends'."""
    lines = []
    for (kind, way, hz), quoted in CPU_PER_MESSAGE.items():
        flow = None if stored is None else stored.flow(flow_key(way, kind, hz))
        cost = None if flow is None else per_message_ms(flow.cpu, hz, flow)
        if stored is None or flow is None or cost is None or cost <= cpu_goal_ms(quoted):
            continue
        publisher, subscriber = _ends(stored, kind, hz)
        if publisher is None or subscriber is None:
            continue
        lines.append(
            f"- {SIZES[kind]} {way} at {hz / 1000:g} kHz: the bridge spent {cost:.3f} ms per "
            f"message{_by_thread(thread_split_ms(hz, flow), cpu_goal_ms(quoted))} An rclpy "
            f"publisher and an rclpy subscriber of the same rate spent {publisher:.3f} + "
            f"{subscriber:.3f} = {publisher + subscriber:.3f} ms: the bridge makes both ends "
            "of a hop, with the conversion between, in one Python process."
        )
    return lines


def _by_thread(split: dict[str, float] | None, bar: float) -> str:
    """Where the bridge's CPU went by thread, and what that leaves the C++ bridge's own thread
    (the end of a sentence)."""
    if split is None:
        return "."
    python = split.get(PYTHON_THREADS, 0.0)
    transports = sum(ms for group, ms in split.items() if group != PYTHON_THREADS)
    others = " and ".join(f"{g} threads {split.get(g, 0.0):.3f}" for g in SPLIT_GROUPS[1:])
    return (
        f", of which its Python threads {python:.3f} ms, {others}. If libzmq's and Fast DDS's "
        f"threads cost the C++ bridge what they cost us ({transports:.3f} ms), its "
        f"{bar:.3f} ms leaves about {max(bar - transports, 0.0):.3f} ms for its callback "
        "thread (the receive, the conversion and the DDS write or ZeroMQ send), the work our "
        f"Python threads do in {python:.3f} ms: out of reach while that work runs in the "
        "interpreter (docs/environment.md, where a small message's CPU goes)."
    )


def clock_notes(stored: Stored | None) -> list[str]:
    """The starvation benchmark's account of where the clock was lost, from its stored run."""
    if stored is None:
        return []
    runs = {}
    for phase in starvation.PHASES:
        flow = stored.flow(phase.name)
        if flow is None and phase.name in starvation.LATER_PHASES:
            continue
        if flow is None:
            return []
        counted = stored_counters(stored.numbers, f"{phase.name} bridge ")
        runs[phase.name] = starvation.ClockRun(phase, flow, counted)
    return starvation.bounds(runs)


def draw(sustained: Stored | None, costs: Stored | None) -> str:
    """Draw the plots and link them (or say why they are not drawn)."""
    try:
        links = []
        if sustained is not None:
            links.append(
                f"![1080p: delivered rate and p99 latency]({plots.sustained_plot(sustained)})"
            )
        if costs is not None:
            links.append(f"![CPU per delivered message per type]({plots.costs_plot(costs)})")
    except ImportError:
        return "Plots not drawn: matplotlib is missing (`make bench` installs `.[bench]`)."
    return "\n\n".join(links)


def provenance(runs: dict[str, Stored]) -> str:
    """Whether the figures shown come from one commit, and if not, which is which."""
    if not runs:
        return "No benchmark has stored figures yet."
    commits = {stored.commit for stored in runs.values()}
    if len(commits) == 1:
        return f"Every figure below comes from commit {commits.pop()} (dates in the last column)."
    newest = max(runs.values(), key=lambda stored: stored.when)
    older = sorted(name for name, stored in runs.items() if stored.commit != newest.commit)
    older_text = " and ".join(f"`{name}`" for name in older)
    return (
        f"**The figures below come from {len(commits)} different commits**: each says the "
        f"commit and date of its run. The newest run is at commit {newest.commit} "
        f"({newest.when}); the figures of {older_text} are older and may not show what that "
        "commit does. `make bench` measures them all again."
    )


def _from(stored: Stored | None) -> str:
    """`` (commit ..., date)``: where a block of figures came from."""
    return "" if stored is None else f" ({stored.measured()})"


def fleet_lines(stored: Stored | None) -> list[str]:
    """The fleet as users run it: per size the CPU per delivered message against the same
    run's rclpy ceiling (issue 36: at most 1.1x), delivery at 25 robots, ``/clock`` at 50, the
    bridge at rest."""
    if stored is None:
        return ["- not measured yet (`benchmarks.fleet`)"]
    numbers = stored.numbers
    lines = []
    ratios = [key for key in numbers if key.startswith("fleet") and key.endswith(".ratio")]
    for robots in sorted(int(key.removeprefix("fleet").split(".")[0]) for key in ratios):
        us, ceiling_us = (
            numbers[f"fleet{robots}.us_per_message"],
            numbers[f"ceiling{robots}.us_per_message"],
        )
        ratio = numbers[f"fleet{robots}.ratio"]
        low, high = numbers[f"fleet{robots}.ratio_min"], numbers[f"fleet{robots}.ratio_max"]
        clock = numbers.get(f"fleet{robots}.delivered.clock")
        lines.append(
            f"- {robots} robots ({1 + 4 * robots} entries): {us:.1f} µs of CPU per delivered "
            f"message, the same run's rclpy ceiling {ceiling_us:.1f} µs: {ratio:.2f}x (goal <= "
            f"{GOAL_RATIO:g}x): {verdict(ratio <= GOAL_RATIO, f'{ratio - GOAL_RATIO:.2f}x')} "
            f"(rounds {low:.2f}-{high:.2f}x; the C++ bridge about {CPP_CEILING_RATIO:g}x, "
            "quoted from issue 36)"
            + ("" if clock is None else f"; /clock delivered {100 * clock:.1f}%")
        )
    at = GOAL_DELIVERED_ROBOTS
    bridge = {
        k: numbers[f"fleet{at}.delivered.{k}"]
        for k in KINDS
        if f"fleet{at}.delivered.{k}" in numbers
    }
    ceiling = {k: numbers.get(f"ceiling{at}.delivered.{k}", 0.0) for k in bridge}
    if bridge:
        short = short_kinds(bridge, ceiling)
        cells = ", ".join(f"{k} {100 * bridge[k]:.1f}% ({100 * ceiling[k]:.1f}%)" for k in bridge)
        lines.append(
            f"- delivered at {at} robots (the ceiling's in brackets): {cells}; goal: every kind "
            f">= {GOAL_DELIVERED:.0%} and never below the ceiling's own: "
            f"{verdict(not short, ', '.join(short))}"
        )
    clock = numbers.get(f"fleet{GOAL_CLOCK_ROBOTS}.delivered.clock")
    if clock is not None:
        gap = f"{100 * (GOAL_CLOCK - clock):.1f} points"
        lines.append(
            f"- /clock at {GOAL_CLOCK_ROBOTS} robots: {100 * clock:.1f}% delivered (goal >= "
            f"{GOAL_CLOCK:.0%}): {verdict(clock >= GOAL_CLOCK, gap)}"
        )
    idle = [key for key in numbers if key.startswith("idle") and key.endswith(".cpu_percent")]
    for key in idle:
        robots = int(key.removeprefix("idle").split(".")[0])
        percent, goal = numbers[key], GOAL_IDLE_PERCENT
        judged = verdict(percent < goal, f"{percent - goal:.2f} points")
        at_rest = idle_ceiling_text(numbers.get(f"idle{robots}.ceiling_cpu_percent"))
        lines.append(
            f"- at rest, {1 + 4 * robots} entries: {percent:.2f}% of a core ({at_rest}; goal < "
            f"{goal:g}%): {judged}"
        )
    return lines


def section(
    sustained: Stored | None,
    costs: Stored | None,
    clock: Stored | None,
    plots_text: str,
    fleet_run: Stored | None = None,
    *,
    busy_run: Stored | None = None,
) -> str:
    """The headline, from the stored runs of ``sustained``, ``costs``, ``starvation``,
    ``fleet`` and ``busy_neighbour``."""
    rows = [*image_rows(sustained), clock_row(clock), *cpu_rows(costs)]
    named = {
        "sustained": sustained, "costs": costs, "starvation": clock, "fleet": fleet_run,
        "busy_neighbour": busy_run,
    }  # fmt: skip
    present = {name: stored for name, stored in named.items() if stored is not None}
    runs = [f"- `{name}`: {stored.run_line()}" for name, stored in present.items()]
    notes = clock_notes(clock)
    cpu_missed = cpu_notes(costs)
    cpu_text = ""
    if cpu_missed:
        cpu_text = (
            f"\nWhat bounds the CPU per message where it misses{_from(costs)}:\n"
            + "\n".join(cpu_missed)
            + "\n"
        )
    return f"""## Headline (issue 15)

Written by `make bench` (`benchmarks.headline`) from the last run of each benchmark (stored in
`benchmarks/results.json`; when and under what load below). Each figure stands beside its
ceiling, measured in the same run: rclpy -> rclpy with the bridge's speed settings. Each
verdict is computed from the figure in its row when this headline is written. The C++
ros_gz_bridge cannot be built here: its figures are quoted from issue 15, which measured it
side by side with this bridge (on this machine type, on another day, at an older commit of
this bridge); none of them is measured by these benchmarks. Details, and every other figure,
in the reports listed below the headline.

{provenance(present)}

{HEADER}
{chr(10).join(rows)}

CPU per delivered message, per type{_from(costs)}: a fixed rate, histories deep enough that
every message arrives; the rclpy columns are the publisher and subscriber processes of
rclpy -> rclpy at the same rate, the same run: what a ROS node in Python spends on each end of
the hop.

{per_type(costs)}

{plots_text}

Where /clock was lost under the flood{_from(clock)}:
{chr(10).join(notes) if notes else "- not measured yet (`benchmarks.starvation`)"}
{cpu_text}
A fleet as users run it (issues 28, 36){_from(fleet_run)}: every figure against the rclpy ceiling
of the same run (details in [its report](benchmarks/reports/fleet.md)):
{chr(10).join(fleet_lines(fleet_run))}

One topic at 20 kHz (issue 36){_from(busy_run)}: against an rclpy publisher of the same run
(details in [its report](benchmarks/reports/busy_neighbour.md)):
{chr(10).join(busy_neighbour.goal_lines(busy_run))}

Measured (2 cores shared with other work: every figure is noisy, the load averages say how
busy the machine was):
{chr(10).join(runs)}
"""


def main(argv: list[str] | None = None) -> int:
    del argv  # no options
    sustained, costs, clock = load("sustained"), load("costs"), load("starvation")
    text = section(
        sustained,
        costs,
        clock,
        draw(sustained, costs),
        load("fleet"),
        busy_run=load("busy_neighbour"),
    )
    write_section("headline", text, first=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())

"""What a fleet costs through one bridge process, as users run it, against the same run's rclpy
ceiling: CPU per delivered message, delivery per kind, threads, memory, start-up.

Usage: ``.venv/bin/python -m benchmarks.fleet [--robots 10 25 50] [--seconds 20] [--rounds 2]``.

Per fleet size N: the C++ peer on Ignition Transport 11 plays the simulator (mode
``pub-fleet``: one process, one node, publishing ``/clock`` at 1 kHz and each robot's odom
50 Hz, imu 200 Hz and joint_states 100 Hz whether or not anyone subscribes, and subscribed to
each robot's ``cmd_vel``; ``testing/fleet_sim.py``). One ``parameter_bridge`` with
``config/fleet_bridge.yaml`` and ``robot=robot_1,...`` (1 + 4N entries). The ROS side lives in
several rclpy processes, as a fleet's does (``benchmarks.fleet_ros``): ``/clock`` in a process
of its own, at most ten robots a process, each taking its topics serialized and counting them,
and publishing its robots' ``cmd_vel`` at 10 Hz. Measured: start-up (from just before the
bridge process starts to every topic having brought a message to its subscriber; the
simulator is already publishing), then over ``--seconds`` the bridge's CPU
(``/proc/<pid>/stat``), what arrived per topic kind against what the schedule offered, the
bridge's threads, RSS at the end and its peak (VmHWM). ``cmd_vel``: what the simulator received
of what the subscribers sent over the whole run.

Beside each bridge round, a ceiling round: one rclpy process (``benchmarks.fleet_ros pub``)
publishing the same ROS topics at the same rates, each message serialized once, and taking
every robot's ``cmd_vel``, with no Gazebo side and no conversion, to the same subscriber
processes; measured the same way. ``--rounds`` pairs of rounds per size, alternating which side
goes first, so that the machine's noise hits both alike; every figure is the median of its
rounds, with their range. Last, the largest fleet's bridge alone (no simulator, no
subscriber): its CPU at rest. The C++ bridge does not run here: issue 36's figures of it are
shown as quoted context, never judged against.
"""

from __future__ import annotations

import argparse
import os
import sys
from collections.abc import Sequence

from benchmarks import plots
from benchmarks.fleet_goals import (
    CPP_CEILING_RATIO,
    CPP_QUOTED,
    GOAL_RATIO,
    KINDS,
    QUOTED,
    Idle,
    Round,
    Size,
    goal_lines,
    idle_ceiling_text,
    median,
    percent,
    rss_context,
    sizes,
    span,
    startup_cell,
    total_offered,
)
from benchmarks.fleet_ros import parts
from benchmarks.fleet_rounds import IDLE_SETTLE, idle_round, run, schedule
from benchmarks.report import link, write_section
from benchmarks.results import store


def _cpu_table(measured: Sequence[Size]) -> list[str]:
    lines = [
        "| robots (entries) | offered msg/s | bridge µs CPU / delivered msg | ceiling µs CPU / "
        f"delivered msg | bridge / ceiling (goal <= {GOAL_RATIO:g}x) | round by round "
        "| bridge CPU, % of a core | ceiling CPU |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for size in measured:
        ratios = ", ".join(f"{ratio:.2f}x" for ratio in size.pair_ratios())
        lines.append(
            f"| {size.robots} ({1 + 4 * size.robots}) | {total_offered(size.robots):,.0f} "
            f"| {span([r.us_per_message for r in size.bridge])} "
            f"| {span([r.us_per_message for r in size.ceiling])} | **{size.ratio:.2f}x** "
            f"| {ratios} | {span([r.cpu for r in size.bridge], unit='%')} "
            f"| {span([r.cpu for r in size.ceiling], unit='%')} |"
        )
    return lines


def _delivered_table(measured: Sequence[Size]) -> list[str]:
    lines = [
        f"| robots | side | {' | '.join(KINDS)} | worst kind in any round |",
        "|---|---|" + "---|" * len(KINDS) + "---|",
    ]
    for size in measured:
        for ceiling in (False, True):
            shares = size.delivered(ceiling)
            cells = " | ".join(percent(shares[kind]) for kind in KINDS)
            side = "rclpy ceiling" if ceiling else "bridge"
            lines.append(f"| {size.robots} | {side} | {cells} | {percent(size.worst(ceiling))} |")
    return lines


def _process_table(measured: Sequence[Size]) -> list[str]:
    lines = [
        "| robots | side | threads | RSS peak MB | RSS end MB | start-up s | subscribers' CPU "
        "| simulator kept |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for size in measured:
        for rows in (size.bridge, size.ceiling):
            started = [r.startup_s for r in rows if r.startup_s is not None]
            never = len(rows) - len(started)
            startup = span(started, 2) + (f"; {never} round(s) never all flowing" if never else "")
            kept = (
                "-" if rows[0].ceiling else span([100 * r.simulator_share for r in rows], unit="%")
            )
            lines.append(
                f"| {size.robots} | {rows[0].who} | {span([r.threads for r in rows], 0)} "
                f"| {span([r.rss_peak for r in rows], 0)} | {span([r.rss for r in rows], 0)} "
                f"| {startup} | {span([r.sub_cpu for r in rows], unit='%')} "
                f"({len(parts(size.robots))} processes) | {kept} |"
            )
    return lines


def _rounds_table(rows: Sequence[Round]) -> list[str]:
    lines = [
        "| # | robots | side | 1-min load at start | CPU | messages in window | µs / msg "
        "| worst kind | start-up |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for row in sorted(rows, key=lambda r: r.order):
        head = f"| {row.order} | {row.robots} | {row.who} "
        if row.error:
            lines.append(head + f"| failed: {row.error} |" + " |" * 5)
            continue
        worst = min(row.delivered, key=lambda kind: row.delivered[kind])
        lines.append(
            head + f"| {row.load:.2f} | {row.cpu:.1f}% | {row.messages:,.0f} "
            f"| {row.us_per_message:.1f} | {worst} {percent(row.delivered[worst])} "
            f"| {startup_cell(row)} |"
        )
    return lines


def _quoted_table() -> list[str]:
    lines = [
        "| robots | CPU, C++ | start-up, C++ | delivered, C++ | threads, C++ | RSS, C++ |",
        "|---|---|---|---|---|---|",
    ]
    for count, quoted in CPP_QUOTED.items():
        cells = [quoted.cpu, quoted.startup, quoted.delivered, quoted.threads, quoted.rss]
        lines.append(f"| {count} | " + " | ".join(cell or "-" for cell in cells) + " |")
    return lines


def report(
    rows: Sequence[Round],
    idle: Idle | None,
    args: argparse.Namespace,
    loads: tuple[float, float],
    plot: str,
) -> str:
    robots = " ".join(str(n) for n in args.robots)
    measured = [size for size in sizes(rows) if size.measured]
    lines = [
        "## A fleet as users run it, against the same run's rclpy ceiling (issues 28, 36)",
        "",
        f"Command: `.venv/bin/python -m benchmarks.fleet --robots {robots} --seconds "
        f"{args.seconds:g} --rounds {args.rounds} --idle-seconds {args.idle_seconds:g}`. "
        f"1-minute load average {loads[0]:.2f} before the run and {loads[1]:.2f} after (each "
        "round's in the last table); the machine (2 cores) is shared with other work, so "
        "every figure is noisy: the rounds say by how much.",
        "",
        "The simulator is the C++ peer on Ignition Transport 11 (`testing/peer`, mode "
        "`pub-fleet`: one process, one node) publishing `/clock` at 1 kHz and per robot odom "
        "50 Hz, imu 200 Hz, joint_states 100 Hz (two joints), whether or not anyone "
        "subscribes, each message serialized once; it subscribes to every robot's `cmd_vel`. "
        "One `parameter_bridge` with `config/fleet_bridge.yaml` (1 + 4N entries). The ROS side "
        "is several rclpy processes, as a fleet's is: `/clock` in a process of its own and at "
        "most ten robots a process (10 robots: 2 processes, 25: 4, 50: 6), each taking its "
        "topics serialized (`raw=True`), counting them, and publishing its robots' `cmd_vel` "
        "at 10 Hz. The **rclpy ceiling** is one rclpy process that publishes the same ROS "
        "topics at the same rates (each message serialized once, no Gazebo side, no "
        "conversion) and takes every `cmd_vel`, to the same subscriber processes: what one "
        "rclpy process pays for the fleet's ROS traffic alone, where the bridge sits. Every "
        "process of the run has the executables' Fast DDS profile (`testing/run_env.py`), the "
        "ceiling too, so both sides' writers suppress NACKs alike (docs/environment.md §2). Each "
        f"round: start-up (from the process's start to every topic having brought its "
        f"subscriber a message), then a window of {args.seconds:g} s: CPU (`/proc/<pid>/stat`, "
        "% of one core) and per delivered message (both directions), delivered per kind "
        "against the schedule (`cmd_vel`: what arrived of what the subscribers sent, whole "
        "run), threads, RSS at the end and its peak (VmHWM), the subscribers' CPU, and the "
        "share of its schedule the simulator kept. Shares are of the nominal schedule, so a "
        f"window can show a little over 100%. {args.rounds} round(s) of each side per size, "
        "alternating which goes first; figures are medians, the range of the rounds in "
        "brackets.",
        "",
        *_cpu_table(measured),
        "",
        "Delivered per kind (median of the rounds):",
        "",
        *_delivered_table(measured),
        "",
        "The measured process (the bridge, or the ceiling's one rclpy process):",
        "",
        *_process_table(measured),
        "",
        "Every round, in the order they ran:",
        "",
        *_rounds_table(rows),
    ]
    for row in rows:
        if row.silent_status:
            lines += [
                "",
                f"The bridge's status of the topics that never flowed (round {row.order}, "
                f"{row.robots} robots):",
            ]
            lines += ["", "```", *row.silent_status, "```"]
    lines += [
        "",
        f"Context, not judged: issue 36's table ({QUOTED}). The issue also puts the C++ "
        f"bridge at about {CPP_CEILING_RATIO:g}x an rclpy ceiling like this one on this fleet.",
        "",
        *_quoted_table(),
    ]
    if idle is not None:
        lines += [
            "",
            f"At rest: the bridge of the {idle.robots}-robot YAML ({idle.entries} entries, the "
            "Gazebo -> ROS ones and `cmd_vel` ROS -> Gazebo native) with no simulator and no "
            f"subscriber, measured over {args.idle_seconds:g} s after {IDLE_SETTLE:g} s: "
            f"**{idle.cpu:.2f}% of a core**, {idle.threads} threads, {idle.rss:.0f} MB; then, "
            f"measured the same way, {idle_ceiling_text(idle.ceiling_cpu)} (`fleet_ros pub "
            f"{idle.robots} --at-rest`: the same ROS endpoints, nothing sent). On a virtual "
            "machine whose idle CPUs wake slowly every wake-up costs far more than its work, "
            "so both figures count wake-ups more than code.",
        ]
    lines += ["", "Goals, each judged on this run's figures:", "", *goal_lines(rows, idle)]
    context = rss_context(rows)
    if context:
        lines += ["", context]
    lines += ["", f"![fleet]({link(plot)})"]
    return "\n".join(lines)


def numbers(rows: Sequence[Round], idle: Idle | None = None) -> dict[str, float]:
    """This run's figures for ``benchmarks/results.json``: per size the medians of the rounds
    (``fleet<N>.<figure>``, the ceiling's as ``ceiling<N>.<figure>``), the ratio of the bridge
    to the ceiling and its range over the pairs of rounds; the idle bridge's as
    ``idle<N>.<figure>``."""
    stored: dict[str, float] = {}
    if idle is not None:
        key = f"idle{idle.robots}"
        stored |= {
            f"{key}.cpu_percent": round(idle.cpu, 3),
            f"{key}.threads": idle.threads,
            f"{key}.rss_mb": round(idle.rss, 1),
        }
        if idle.ceiling_cpu is not None:
            stored[f"{key}.ceiling_cpu_percent"] = round(idle.ceiling_cpu, 3)
    for size in sizes(rows):
        if not size.measured:
            continue
        ratios = size.pair_ratios()
        stored |= {
            f"fleet{size.robots}.ratio": round(size.ratio, 3),
            f"fleet{size.robots}.ratio_min": round(min(ratios), 3),
            f"fleet{size.robots}.ratio_max": round(max(ratios), 3),
            f"fleet{size.robots}.rounds": len(size.bridge),
        }
        for key, side in (("fleet", size.bridge), ("ceiling", size.ceiling)):
            name = f"{key}{size.robots}"
            started = [r.startup_s for r in side if r.startup_s is not None]
            stored |= {
                f"{name}.cpu_percent": round(median([r.cpu for r in side]), 2),
                f"{name}.us_per_message": round(median([r.us_per_message for r in side]), 2),
                f"{name}.threads": max(r.threads for r in side),
                f"{name}.rss_mb": round(median([r.rss for r in side]), 1),
                f"{name}.rss_peak_mb": round(max(r.rss_peak for r in side), 1),
                f"{name}.subscriber_cpu_percent": round(median([r.sub_cpu for r in side]), 2),
                **{
                    f"{name}.delivered.{kind}": round(share, 4)
                    for kind, share in size.delivered(key == "ceiling").items()
                },
            }
            if started:
                stored[f"{name}.startup_s"] = round(median(started), 3)
        stored[f"fleet{size.robots}.simulator_share"] = round(
            median([r.simulator_share for r in size.bridge]), 4
        )
    return stored


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--robots", type=int, nargs="+", default=[10, 25, 50])
    parser.add_argument("--seconds", type=float, default=20.0)
    parser.add_argument(
        "--rounds", type=int, default=2, help="rounds of each side per size, alternating"
    )
    parser.add_argument(
        "--idle-seconds", type=float, default=20.0, help="the idle bridge's window; 0: none"
    )
    args = parser.parse_args(argv)
    load = os.getloadavg()[0]
    order = schedule(args.robots, args.rounds)
    rows = [run(count, args.seconds, ceiling, n) for n, (count, ceiling) in enumerate(order, 1)]
    idle = idle_round(max(args.robots), args.idle_seconds) if args.idle_seconds > 0 else None
    store("fleet", {}, load, numbers(rows, idle))
    plot = plots.fleet_plot(rows)
    write_section("fleet", report(rows, idle, args, (load, os.getloadavg()[0]), plot))
    return 0


if __name__ == "__main__":
    sys.exit(main())

"""What a fleet costs in one bridge process: CPU, delivery, threads, memory, start-up.

Usage: ``.venv/bin/python -m benchmarks.fleet [--robots 10 25 50] [--seconds 20]``.

Per fleet size N: the C++ peer on Ignition Transport 11 plays the simulator (mode
``pub-fleet``: one process, one node, publishing ``/clock`` at 1 kHz and each robot's odom
50 Hz, imu 200 Hz and joint_states 100 Hz whether or not anyone subscribes, and subscribed to
each robot's ``cmd_vel``; ``testing/fleet_sim.py``). One ``parameter_bridge`` with
``config/fleet_bridge.yaml`` and ``robot=robot_1,...`` (1 + 4N entries). One rclpy process
(``benchmarks.fleet_ros sub``) takes every ROS topic serialized and counts per topic, and
publishes every robot's ``cmd_vel`` at 10 Hz. Measured: start-up (from just before the bridge
process starts to every topic having brought a message to that subscriber; the simulator is
already publishing), then over ``--seconds`` the bridge's CPU (``/proc/<pid>/stat``), what
arrived per topic kind against what the schedule offered, the bridge's threads and RSS at the
end. ``cmd_vel``: what the simulator received of what the subscriber sent over the whole run.
Beside it, the same run's rclpy ceiling: one rclpy process (``benchmarks.fleet_ros pub``)
publishing the same ROS topics at the same rates, each message serialized once, with no
Gazebo side and no conversion, to the same subscriber. Last, the largest fleet's bridge alone
(no simulator, no subscriber): its CPU at rest. The C++ bridge is not installable here: its
figures are quoted from issue 28.
"""

from __future__ import annotations

import argparse
import os
import sys
from collections.abc import Sequence

from benchmarks import plots
from benchmarks.fleet_goals import (
    CPP_QUOTED,
    QUOTED,
    Idle,
    Round,
    delivered_cell,
    goal_lines,
    percent,
    quoted_cell,
    startup_cell,
    total_offered,
)
from benchmarks.fleet_rounds import IDLE_SETTLE, idle_round, run
from benchmarks.report import write_section
from benchmarks.results import store


def report(
    rows: Sequence[Round], idle: Idle | None, args: argparse.Namespace, load: float, plot: str
) -> str:
    robots = " ".join(str(n) for n in args.robots)
    lines = [
        "## A fleet in one process (issue 28)",
        "",
        f"Command: `.venv/bin/python -m benchmarks.fleet --robots {robots} --seconds "
        f"{args.seconds:g}`. 1-minute load average before the run: {load:.2f}; the machine "
        "(2 cores) is shared with other work, so every figure is noisy.",
        "",
        "The simulator is the C++ peer on Ignition Transport 11 (`testing/peer`, mode `pub-fleet`: "
        "one process, one node) publishing `/clock` at 1 kHz and per robot odom 50 Hz, imu "
        "200 Hz, joint_states 100 Hz (two joints), whether or not anyone subscribes, each "
        "message serialized once; it subscribes to every robot's `cmd_vel`. One "
        "`parameter_bridge` with `config/fleet_bridge.yaml` (1 + 4N entries). One rclpy process "
        "subscribes to every ROS topic taking the messages serialized (`raw=True`), counts per "
        "topic, and publishes each robot's `cmd_vel` at 10 Hz. Start-up: from just before the "
        "bridge process starts to every topic having brought a message to that subscriber. "
        f"Then a window of {args.seconds:g} s: the bridge's CPU (`/proc/<pid>/stat`, % of one "
        "core) and per delivered message (both directions), delivered per kind against the "
        "schedule (`cmd_vel`: received by the simulator of what the subscriber sent, whole "
        "run), threads and RSS at the end, the subscriber's own CPU, and the share of its "
        "schedule the simulator kept. Shares are of the nominal schedule, so a window can "
        "show a little over 100%. Where the ceiling below loses the same kind, the limit is "
        "the one rclpy subscriber (reliable, keep-last 10: at 1 kHz, `/clock` overwrites what "
        "it has not taken), not the bridge.",
        "",
        "| robots (entries) | offered msg/s | bridge CPU | µs CPU / delivered msg | start-up s "
        "| delivered clock / odom / imu / joint_states / cmd_vel | threads | RSS MB "
        "| subscriber CPU | simulator kept |",
        "|---|---|---|---|---|---|---|---|---|---|",
    ]
    for row in rows:
        if row.ceiling:
            continue
        head = f"| {row.robots} ({1 + 4 * row.robots}) | {total_offered(row.robots):,.0f} "
        if row.error:
            lines.append(head + f"| failed: {row.error} |" + " |" * 7)
            continue
        lines.append(
            head + f"| {row.cpu:.1f}% | {row.us_per_message:.1f} | {startup_cell(row)} "
            f"| {delivered_cell(row)} | {row.threads} | {row.rss:.0f} | {row.sub_cpu:.1f}% "
            f"| {percent(row.simulator_share)} |"
        )
    for row in rows:
        if row.silent_status:
            lines += [
                "",
                f"The bridge's status of the topics that never flowed ({row.robots} robots):",
            ]
            lines += ["", "```", *row.silent_status, "```"]
    lines += [
        "",
        "The same run's rclpy ceiling: one rclpy process publishing the same ROS topics at the "
        "same rates (each message serialized once, no Gazebo side, no conversion) to the same "
        "subscriber: what one rclpy process pays for the fleet's ROS traffic alone.",
        "",
        "| robots | rclpy publisher CPU | µs CPU / delivered msg | delivered clock / odom / imu "
        "/ joint_states | threads | RSS MB | subscriber CPU |",
        "|---|---|---|---|---|---|---|",
    ]
    for row in rows:
        if not row.ceiling:
            continue
        if row.error:
            lines.append(f"| {row.robots} | failed: {row.error} |" + " |" * 5)
            continue
        lines.append(
            f"| {row.robots} | {row.cpu:.1f}% | {row.us_per_message:.1f} | {delivered_cell(row)} "
            f"| {row.threads} | {row.rss:.0f} | {row.sub_cpu:.1f}% |"
        )
    lines += [
        "",
        f"Issue 28's table ({QUOTED}): the C++ bridge beside ours of then.",
        "",
        "| robots | offered msg/s (the issue's count) | CPU C++ (ours then) "
        "| µs CPU / delivered msg, C++ | start-up s, C++ | delivered, C++ | threads, C++ "
        "| RSS MB, C++ |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for count, quoted in CPP_QUOTED.items():
        lines.append(
            f"| {count} | ~{quoted.offered:,.0f} | {quoted.cpu_cpp:g}% ({quoted.cpu_ours:g}%) "
            f"| {quoted.cpp_us_per_message():.1f} "
            f"| {quoted_cell(*quoted.startup_cpp)} "
            f"| {quoted_cell(*[100 * d for d in quoted.delivered_cpp], unit='%')} "
            f"| {quoted.threads_cpp} | {quoted.rss_cpp:g} |"
        )
    if idle is not None:
        lines += [
            "",
            f"At rest: the bridge of the {idle.robots}-robot YAML ({idle.entries} entries, the "
            "Gazebo -> ROS ones and `cmd_vel` ROS -> Gazebo native) with no simulator and no "
            f"subscriber, measured over {args.idle_seconds:g} s after {IDLE_SETTLE:g} s: "
            f"**{idle.cpu:.2f}% of a core**, {idle.threads} threads, {idle.rss:.0f} MB.",
        ]
    lines += [
        "",
        "Issue 28's goals, on this run:",
        "",
        *goal_lines(rows, idle),
        "",
        f"![fleet]({plot})",
    ]
    return "\n".join(lines)


def numbers(rows: Sequence[Round], idle: Idle | None = None) -> dict[str, float]:
    """This run's figures for ``benchmarks/results.json`` (``fleet<N>.<figure>``; the
    ceiling's as ``ceiling<N>.<figure>``; the idle bridge's as ``idle<N>.<figure>``)."""
    stored: dict[str, float] = {}
    if idle is not None:
        key = f"idle{idle.robots}"
        stored |= {
            f"{key}.cpu_percent": round(idle.cpu, 3),
            f"{key}.threads": idle.threads,
            f"{key}.rss_mb": round(idle.rss, 1),
        }
    for row in rows:
        if row.error:
            continue
        key = f"{'ceiling' if row.ceiling else 'fleet'}{row.robots}"
        stored |= {
            f"{key}.cpu_percent": round(row.cpu, 2),
            f"{key}.us_per_message": round(row.us_per_message, 2),
            f"{key}.threads": row.threads,
            f"{key}.rss_mb": round(row.rss, 1),
            f"{key}.subscriber_cpu_percent": round(row.sub_cpu, 2),
            **{f"{key}.delivered.{k}": round(v, 4) for k, v in row.delivered.items()},
        }
        if not row.ceiling:
            if row.startup_s is not None:
                stored[f"{key}.startup_s"] = round(row.startup_s, 3)
            stored[f"{key}.silent_topics"] = len(row.silent)
            stored[f"{key}.simulator_share"] = round(row.simulator_share, 4)
    return stored


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--robots", type=int, nargs="+", default=[10, 25, 50])
    parser.add_argument("--seconds", type=float, default=20.0)
    parser.add_argument(
        "--idle-seconds", type=float, default=20.0, help="the idle bridge's window; 0: none"
    )
    args = parser.parse_args(argv)
    load = os.getloadavg()[0]
    rows = [run(count, args.seconds, ceiling) for count in args.robots for ceiling in (False, True)]
    idle = idle_round(max(args.robots), args.idle_seconds) if args.idle_seconds > 0 else None
    store("fleet", {}, load, numbers(rows, idle))
    plot = plots.fleet_plot(rows, CPP_QUOTED)
    write_section("fleet", report(rows, idle, args, load, plot))
    return 0


if __name__ == "__main__":
    sys.exit(main())

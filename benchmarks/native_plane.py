"""The native data plane against the Python path, each in a bridge process of its own (issue 22).

Usage: ``.venv/bin/python -m benchmarks.native_plane [--seconds S] [--workload-seconds S]
[--workload-rounds N] [--clock-seconds S] [--rates HZ ...]``; writes the report
``benchmarks/reports/native_plane.md``, stores its figures and draws
``benchmarks/plots/native_overload.png``.
Each phase runs with the native data plane (the default where the extension is built) and with
``ROS_GZ_BRIDGE_NATIVE=off`` in the bridge's environment (the Python path), a fresh bridge
each time; the status table (SIGUSR1) says which path each channel took and what it received,
published and dropped. The Gazebo ends are the C++ peer on Ignition Transport 11.

1. Overload: Odometry Gazebo -> ROS offered at rising rates to an rclpy subscriber.
2. The TurtleBot3 workload through the unchanged seed configuration: the bridge's CPU.
3. /clock at 1 kHz while Odometry floods the same Gazebo process and the same bridge.

Each phase is a module of its own (``native_overload``, ``native_workload``, ``native_clock``);
the section ends with the proxy goal judged on the last ``costs`` run (``native_proxy``).
"""

from __future__ import annotations

import argparse
import itertools
import os
import sys

from benchmarks.harness import GZ_ENDS, FlowResult
from benchmarks.native_clock import (
    CLOCK_HEADER,
    CLOCK_HZ,
    FLOOD_HZ,
    FLOOD_LEAD,
    ClockRun,
    clock_goal,
    clock_row,
    clock_under_flood,
)
from benchmarks.native_overload import (
    OVERLOAD_HEADER,
    OVERLOAD_RATES,
    QUEUE,
    SUBSCRIBERS,
    Point,
    overload_goals,
    plot,
    point_row,
    sweep,
)
from benchmarks.native_paths import PATHS
from benchmarks.native_proxy import GOAL_PROXY, proxy_lines
from benchmarks.native_workload import (
    STREAMS,
    TURTLEBOT_CHANNELS,
    WORKLOAD_HEADER,
    Workload,
    median_run,
    workload,
    workload_goal,
    workload_row,
)
from benchmarks.report import write_section
from benchmarks.results import store


def section(
    points: list[Point], runs: list[Workload], clocks: list[ClockRun], args: argparse.Namespace
) -> str:
    flags = (
        f" --seconds {args.seconds:g} --workload-seconds {args.workload_seconds:g}"
        f" --workload-rounds {args.workload_rounds}"
        f" --clock-seconds {args.clock_seconds:g}"
    )
    rates = ", ".join(f"{hz / 1000:g}" for hz in args.rates)
    streams = ", ".join(f"/{s.topic} ({s.gz_type}) at {s.hz:g} Hz" for s in STREAMS)
    return f"""## The native data plane against the Python path (issue 22)

Command: `.venv/bin/python -m benchmarks.native_plane{flags}`

Every phase runs twice, each time in a fresh bridge process: with the native data plane (on
by default where the extension is built, docs/native.md) and with `ROS_GZ_BRIDGE_NATIVE=off`
in the bridge's environment (the Python path). The PATH column is the bridge's own status
table (SIGUSR1), as are its in / out / dropped counters over the row; on both paths "in"
counts the messages the channel took from its queue, "dropped" those the queue let go,
oldest first, before any work on them. Bridge CPU is % of one core over the publishing window
(/proc/<pid>/stat), split by thread (/proc/<pid>/task/<tid>/schedstat): the Python threads
(on the native path also the C loop, which runs on the channel's reader thread with the GIL
released), libzmq's I/O thread, Fast DDS's threads. Machine CPU: all {os.cpu_count()} cores'
busy time over the same window, % of all of them (wall time less /proc/stat's idle time;
other work on the machine included). {GZ_ENDS}

### 1. Overload: Odometry Gazebo -> ROS at rising offered rates

The C++ peer offers Odometry at {rates} kHz for {args.seconds:g} s each (paced, serialized
anew each time) through one channel with queues of {QUEUE} (YAML `publisher_queue` /
`subscriber_queue`, as `costs`' rows) to an rclpy subscriber of depth {QUEUE}, a fresh bridge
for each path and subscriber: the *rclpy* subscriber deserializes every message (as an
application does, and so tops out at its own rate on these cores); the *serialized* one takes
them serialized (`raw=True`) and reads only the stamp, so what it misses is what the bridge did
not carry. Delivered = what the subscriber received per second of publishing; CPU per
delivered message = bridge CPU / delivered rate.

{OVERLOAD_HEADER}
{chr(10).join(point_row(point) for point in points)}

{plot(points)}

Goals (issue 22):
{chr(10).join(overload_goals(points))}

### 2. The TurtleBot3 workload through the seed configuration

`config/turtlebot3_waffle_bridge.yaml` unchanged ({TURTLEBOT_CHANNELS} channels); one C++ peer
process per stream, Harmonic type names on the wire: {streams}; the other entries (scan,
camera_info, cmd_vel) stay idle. One rclpy process subscribes to the five topics (reliable,
keep-last 10, the bridge's default). Bridge CPU over {args.workload_seconds:g} s while all
streams publish; {args.workload_rounds} rounds a path, alternating, each with a fresh bridge (the
figure moves by a few points from run to run on these shared cores: the median is judged).

{WORKLOAD_HEADER}
{chr(10).join(workload_row(run) for run in runs)}

Goal (issue 22):
{workload_goal(runs)}

### 3. /clock at 1 kHz while Odometry floods the same Gazebo process and bridge

One Gazebo publisher process sends /clock at {CLOCK_HZ:g} Hz for {args.clock_seconds:g} s and,
from another thread (`kind-pub --flood`), Odometry at {FLOOD_HZ / 1000:g} kHz from
{FLOOD_LEAD:g} s before the first clock message; one bridge carries both (command-line
entries, default queues), each to an rclpy subscriber of depth 10.

{CLOCK_HEADER}
{chr(10).join(clock_row(run) for run in clocks)}

Goal (issue 22):
{clock_goal(clocks)}

### CPU per message against the rclpy ends (issue 22's proxy)

Goal: bridge CPU per message <= {GOAL_PROXY:g} x (rclpy publisher + rclpy subscriber CPU per
message at the same rate, the same run), judged on the Gazebo -> ROS rows of the
[`costs` report](costs.md) (its bridge ran with the native data plane on, the default).
{chr(10).join(proxy_lines())}
"""


def _stored(
    points: list[Point], runs: list[Workload], clocks: list[ClockRun]
) -> tuple[dict[str, FlowResult], dict[str, float]]:
    """The flows and figures kept in ``benchmarks/results.json``."""
    flows = {f"overload {p.path} {p.subscriber} {p.hz:g}": p.result for p in points}
    flows |= {f"clock {run.path}": run.result for run in clocks}
    medians = [run for path in PATHS if (run := median_run(runs, path)) is not None]
    numbers = {f"workload {run.path} cpu": run.cpu for run in medians if run.cpu is not None}
    for run in medians:
        for topic, count in (run.received or {}).items():
            numbers[f"workload {run.path} {topic} received"] = float(count)
            numbers[f"workload {run.path} {topic} sent"] = float((run.sent or {})[topic])
    return flows, numbers


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--seconds", type=float, default=2.0, help="publishing per offered rate")
    parser.add_argument("--workload-seconds", type=float, default=10.0, help="CPU window")
    parser.add_argument(
        "--workload-rounds", type=int, default=3, help="workload runs per path (median judged)"
    )
    parser.add_argument("--clock-seconds", type=float, default=5.0, help="clock publishing")
    parser.add_argument("--rates", type=float, nargs="+", default=list(OVERLOAD_RATES))
    args = parser.parse_args(argv)
    load_before = os.getloadavg()[0]
    points = [
        point
        for path, subscriber in itertools.product(PATHS, SUBSCRIBERS)
        for point in sweep(path, subscriber, args.seconds, sorted(args.rates))
    ]
    runs = [
        workload(path, args.workload_seconds) for _ in range(args.workload_rounds) for path in PATHS
    ]
    clocks = [clock_under_flood(path, args.clock_seconds) for path in PATHS]
    write_section("native_plane", section(points, runs, clocks, args))
    flows, numbers = _stored(points, runs, clocks)
    store("native_plane", flows, load_before, numbers)
    return 0


if __name__ == "__main__":
    sys.exit(main())

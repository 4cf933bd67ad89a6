"""Discovered bridging at scale (issue 16): how soon a new Gazebo topic exists in ROS, and what
the bridge costs while it holds 10, 100 or 1,000 discovered topics that nobody reads.

Usage: ``.venv/bin/python -m benchmarks.discovery [--counts 10 100 1000] [--idle 10]``.

Per count N: one Gazebo process (``benchmarks.discovery_topics``, our ZeroMQ node) advertises
N topics; ``parameter_bridge -p auto_bridge:=true`` (lazy: nothing is subscribed in Gazebo,
nothing converted) bridges them. Measured: the time until all N ROS topics exist; then, with
no change, the bridge's CPU (percent of one core from /proc over ``--idle`` seconds) and RSS;
then ten times, at random moments, a new Gazebo topic is advertised and an rclpy node polls the
ROS graph every 5 ms until the topic is there (time from the advertisement, CLOCK_MONOTONIC in
both processes). The bridge scans the graph every 0.5 s, so on average about 0.25 s of each
latency is the wait for its next scan.
"""

from __future__ import annotations

import argparse
import os
import statistics
import sys
import tempfile
import time
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import rclpy
from rclpy.node import Node

from benchmarks.harness import BIN, CpuWindow, topic_name
from benchmarks.report import write_section
from testing.gzpeer import start_process, stop_processes, wait_for_line
from testing.procstat import rss_mb
from testing.run_env import run_env

NEW_TOPICS = 10
POLL = 0.005


@dataclass(frozen=True)
class Row:
    count: int
    all_bridged_s: float
    idle_cpu: float
    rss_mb: float
    latencies_ms: tuple[float, ...]


def _ros_names(node: Node) -> set[str]:
    return {name for name, _ in node.get_topic_names_and_types()}


def _wait_for(node: Node, wanted: set[str], timeout: float) -> float:
    """Seconds until every name in ``wanted`` is in the ROS graph (monotonic time of that)."""
    deadline = time.monotonic() + timeout
    while not wanted <= _ros_names(node):
        if time.monotonic() > deadline:
            missing = len(wanted - _ros_names(node))
            msg = f"{missing} of {len(wanted)} topics not in ROS after {timeout} s"
            raise TimeoutError(msg)
        time.sleep(POLL)
    return time.monotonic()


def measure(node: Node, count: int, idle: float, workdir: Path) -> Row:
    prefix = topic_name(f"disc{count}")
    start_file = workdir / f"start-{count}"
    gazebo = start_process(
        [sys.executable, "-m", "benchmarks.discovery_topics", prefix, str(count),
         str(NEW_TOPICS), str(start_file)],
        run_env(),
    )  # fmt: skip
    try:
        wait_for_line(gazebo, "^READY", timeout=60)
        bridge = start_process(
            [str(BIN / "parameter_bridge"), "--ros-args", "-p", "auto_bridge:=true",
             "-p", f"auto_bridge_allow:=[^{prefix}/]"],
            run_env(),
        )  # fmt: skip
        started = time.monotonic()
        names = {f"{prefix}/t{i}" for i in range(count)}
        all_bridged = _wait_for(node, names, 60 + count * 0.1) - started
        time.sleep(2.0)  # let start-up work settle
        window = CpuWindow(bridge.pid)
        window.begin()
        time.sleep(idle)
        window.end()
        rss = rss_mb(bridge.pid)
        start_file.touch()
        latencies = []
        for j in range(NEW_TOPICS):
            advertised = float(wait_for_line(gazebo, rf"^ADVERTISED new{j} (\S+)").group(1))
            appeared = _wait_for(node, {f"{prefix}/new{j}"}, 30)
            latencies.append(1000 * (appeared - advertised))
        return Row(count, all_bridged, window.percent or 0.0, rss, tuple(latencies))
    finally:
        stop_processes()


def report(rows: Sequence[Row], idle: float, load: float) -> str:
    lines = [
        "## Discovered bridging at scale (issue 16)",
        "",
        f"Command: `.venv/bin/python -m benchmarks.discovery --idle {idle:g}`",
        "",
        "One Gazebo process (our ZeroMQ node) advertises N `gz.msgs.StringMsg` topics, never "
        "published; `parameter_bridge -p auto_bridge:=true` bridges them to ROS, lazily (no ROS "
        "subscriber, so nothing is subscribed in Gazebo or converted). *All bridged*: from the "
        "bridge's start until the benchmark's rclpy node sees the N ROS topics (this includes "
        "the bridge's start-up and DDS discovery between the two processes, which varies most "
        "from run to run). *Idle CPU* (% of one core, from "
        f"/proc over {idle:g} s) and *RSS* of the bridge once everything is bridged. *New topic*: "
        f"{NEW_TOPICS} times, at random moments, one more Gazebo topic is advertised and an rclpy "
        "node polls the ROS graph every 5 ms: time from the advertisement to the ROS topic "
        "(median and worst). The bridge scans the graph every 0.5 s: 0-0.5 s of each time is "
        "the wait for its next scan. "
        f"1-minute load average before the run: {load:.2f}; the machine (2 cores) was shared "
        "with other developers' work, which skews every number.",
        "",
        "| discovered topics | all bridged s | idle CPU % | RSS MB | new topic median ms "
        "| new topic worst ms |",
        "|---|---|---|---|---|---|",
    ]
    for row in rows:
        lines.append(
            f"| {row.count:,} | {row.all_bridged_s:.1f} | {row.idle_cpu:.1f} | "
            f"{row.rss_mb:.0f} | {statistics.median(row.latencies_ms):.0f} | "
            f"{max(row.latencies_ms):.0f} |"
        )
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--counts", type=int, nargs="+", default=[10, 100, 1000])
    parser.add_argument("--idle", type=float, default=10.0)
    args = parser.parse_args(argv)
    load = os.getloadavg()[0]
    os.environ.update(run_env())  # the same domain and settings as the processes it starts
    rclpy.init()
    node = Node("discovery_bench")
    rows = []
    try:
        for count in args.counts:
            print(f"== {count} topics", file=sys.stderr, flush=True)
            with tempfile.TemporaryDirectory() as workdir:
                rows.append(measure(node, count, args.idle, Path(workdir)))
            print(rows[-1], file=sys.stderr, flush=True)
    finally:
        node.destroy_node()
        rclpy.try_shutdown()
    write_section("discovery", report(rows, args.idle, load))
    return 0


if __name__ == "__main__":
    sys.exit(main())

"""The first service call (issue 23): a ROS client calling a forwarded Gazebo service the moment
it is discoverable.

Usage: ``.venv/bin/python -m benchmarks.first_call [--runs 10] [--sleep 0]``.

Per run: the C++ peer on Ignition Transport 11 offers ``ControlWorld``'s Gazebo service (mode
reply, Fortress type names); a fresh ``parameter_bridge`` forwards it; this process's rclpy
client polls ``service_is_ready`` every millisecond from the bridge's start (or, with
``--sleep S``, sleeps S seconds first and then waits, as upstream's ``ROSClientTest`` does
with 1 s), calls once and spins until the answer. Measured: the time from the bridge's start
until the service is ready for the client, and the first call's latency (call to answer). A
request or reply lost and resent on Fast DDS's periodic heartbeat (3 s) shows as a latency of
seconds.
"""

from __future__ import annotations

import argparse
import os
import statistics
import sys
import time
from collections.abc import Sequence
from dataclasses import dataclass

import rclpy
from rclpy.node import Node
from ros_gz_interfaces.srv import ControlWorld

from benchmarks.harness import BIN, topic_name
from benchmarks.report import write_section
from benchmarks.startup import CREATING, LOG_ENV
from testing.gzpeer import start_peer, start_process, stop_processes, wait_for_line
from testing.run_env import run_env

POLL = 0.001
#: A first call slower than this was resent (the next heartbeat), not just slow.
RESENT_S = 1.0


@dataclass(frozen=True)
class Run:
    created_s: float
    ready_s: float
    latency_s: float
    success: bool


def one_run(node: Node, sleep: float) -> Run:
    service = topic_name("first_call")
    try:
        replier = start_peer(
            "reply", service, "ignition.msgs.WorldControl", "ignition.msgs.Boolean", "60",
            env=run_env(),
        )  # fmt: skip
        wait_for_line(replier, "^READY", timeout=30)
        client = node.create_client(ControlWorld, service)
        started, started_wall = time.monotonic(), time.time()
        bridge = start_process(
            [str(BIN / "parameter_bridge"),
             f"{service}@ros_gz_interfaces/srv/ControlWorld@ignition.msgs.WorldControl"
             "@ignition.msgs.Boolean"],
            run_env() | LOG_ENV,
        )  # fmt: skip
        time.sleep(sleep)
        while not client.service_is_ready():
            rclpy.spin_once(node, timeout_sec=POLL)
            if time.monotonic() - started > 30:
                msg = "the bridge's service was not ready within 30 s"
                raise TimeoutError(msg)
        ready = time.monotonic()
        future = client.call_async(ControlWorld.Request())
        rclpy.spin_until_future_complete(node, future, timeout_sec=30)
        answered = time.monotonic()
        response = future.result()
        node.destroy_client(client)
        created = float(wait_for_line(bridge, CREATING.pattern).group(1)) - started_wall
        success = bool(response and response.success)
        return Run(created, ready - started, answered - ready, success)
    finally:
        stop_processes()


def report(runs: Sequence[Run], args: argparse.Namespace, load: float) -> str:
    latencies = [run.latency_s for run in runs]
    resent = sum(latency > RESENT_S for latency in latencies)
    waited = f"sleeps {args.sleep:g} s after the bridge's start, then " if args.sleep else ""
    lines = [
        "## First service call (issue 23)",
        "",
        f"Command: `.venv/bin/python -m benchmarks.first_call --runs {args.runs} "
        f"--sleep {args.sleep:g}`",
        "",
        "A fresh `parameter_bridge` forwards `ros_gz_interfaces/srv/ControlWorld` to the C++ "
        "peer's Gazebo service (Ignition Transport 11, Fortress type names); an rclpy client "
        f"{waited}polls `service_is_ready` every millisecond and calls once the moment it is "
        "ready. *Service created*: the bridge's `Creating` line, *ready*: `service_is_ready`, "
        "both seconds from the bridge's start; *first call*: call to answer. A call "
        f"over {RESENT_S:g} s was lost once and resent on Fast DDS's 3 s heartbeat. "
        f"1-minute load average before the run: {load:.2f}.",
        "",
        "| runs | answered success | service created s median (max) | ready s median (max) "
        "| first call ms median | first call ms max | calls over 1 s |",
        "|---|---|---|---|---|---|---|",
        f"| {len(runs)} | {sum(run.success for run in runs)} | "
        f"{statistics.median(run.created_s for run in runs):.2f} "
        f"({max(run.created_s for run in runs):.2f}) | "
        f"{statistics.median(run.ready_s for run in runs):.2f} "
        f"({max(run.ready_s for run in runs):.2f}) | "
        f"{1000 * statistics.median(latencies):.1f} | {1000 * max(latencies):.1f} | {resent} |",
        "",
        "First-call latencies, ms, in run order: "
        + ", ".join(f"{1000 * latency:.0f}" for latency in latencies),
    ]
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--runs", type=int, default=10)
    parser.add_argument("--sleep", type=float, default=0.0)
    args = parser.parse_args(argv)
    load = os.getloadavg()[0]
    os.environ.update(run_env())  # the same domain and settings as the processes it starts
    rclpy.init()
    node = Node("first_call_bench")
    runs = []
    try:
        for _ in range(args.runs):
            runs.append(one_run(node, args.sleep))
            print(runs[-1], file=sys.stderr, flush=True)
    finally:
        node.destroy_node()
        rclpy.try_shutdown()
    write_section("first_call", report(runs, args, load))
    return 0


if __name__ == "__main__":
    sys.exit(main())

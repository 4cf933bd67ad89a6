"""Does one process carry Odometry at 20 kHz, quiet and with a busy loop beside it (issue 36)?

Usage: ``.venv/bin/python -m benchmarks.busy_neighbour [--seconds 4] [--rounds 2]``.

The C++ peer offers Odometry at 20 kHz (serialized anew each time, as a simulator does) for a
few seconds through one native Gazebo -> ROS channel (queues of 1000, as ``costs``' rows) to an
rclpy subscriber of depth 1000 that takes the messages serialized (``raw=True``) and reads
only the stamp, a fresh bridge each round. The yardstick of the same run: an rclpy publisher
in one process offering the same rate to the same subscriber, no bridge (the ceiling: what a
bare ROS publisher delivers on these cores). Each round runs the bridge and the ceiling, in
alternating order, first on a quiet machine, then with a busy loop (``yes``: one process at
100% of a core) beside them all along. The bridge's own counters over the round (IN, OUT and
DROPPED of its SIGUSR1 status table) say where a message was lost: before the bridge (the
Gazebo publisher's send queue), in the bridge's queue, or after it (the subscriber's history,
when its process does not take them as fast as they come).
"""

from __future__ import annotations

import argparse
import os
from collections.abc import Sequence

from benchmarks.bridged import bridge_process, flow_through
from benchmarks.busy_loops import busy_loops
from benchmarks.harness import Flow, FlowResult, bridge_config, run_flow, topic_name
from benchmarks.native_overload import QUEUE
from benchmarks.native_paths import (
    Counters,
    counted_since,
    counters,
    path_backend,
    stored_counters,
)
from benchmarks.report import write_section
from benchmarks.results import Stored, load, store
from benchmarks.tables import verdict
from testing.run_env import run_env

#: The offered rate, and the share of it the goal asks for (issue 36).
HZ, GOAL_SHARE = 20000.0, 0.95
#: The two conditions, in the order they run.
CONDITIONS = ("quiet", "busy")
LABELS = {"quiet": "quiet", "busy": "beside a busy loop"}


def _flow(publisher: str, seconds: float) -> Flow:
    return Flow(publisher, "ros-sub", "odometry", seconds, HZ, depth=QUEUE, raw=True)


def bridged(seconds: float) -> tuple[FlowResult, Counters | None]:
    """One round through a fresh bridge: the flow, and the channel's counters over it."""
    native = path_backend("native")
    topic = topic_name("busy_neighbour")
    arguments = bridge_config([(topic, "odometry", "gz2ros")], QUEUE)
    with bridge_process(arguments, native.bridge_env, channels=1) as bridge:
        before = counters(bridge, [topic])
        result = flow_through(_flow("gz-pub", seconds), topic, native, bridge)
        after = counters(bridge, [topic])
    return result, counted_since(before, after, topic)


def ceiling(seconds: float) -> FlowResult:
    """One round of the rclpy publisher straight to the same subscriber."""
    return run_flow(_flow("ros-pub", seconds), topic_name("busy_neighbour_ceiling"), run_env())


def measure(seconds: float, rounds: int) -> tuple[dict[str, FlowResult], dict[str, float]]:
    """The flows by ``who.condition.round`` and the bridge's counters by
    ``bridge.condition.round.in|out|dropped``."""
    flows: dict[str, FlowResult] = {}
    numbers: dict[str, float] = {}
    for condition in CONDITIONS:
        with busy_loops(1 if condition == "busy" else 0):
            for index in range(rounds):
                order = ("bridge", "ceiling") if index % 2 == 0 else ("ceiling", "bridge")
                for who in order:
                    key = f"{who}.{condition}.{index}"
                    if who == "ceiling":
                        flows[key] = ceiling(seconds)
                        continue
                    flows[key], counted = bridged(seconds)
                    if counted is not None:
                        numbers |= counted.numbers(f"{key}.")
                    print(key, flows[key], counted, flush=True)
    return flows, numbers


def _rounds(stored: Stored, who: str, condition: str) -> list[tuple[str, FlowResult]]:
    prefix = f"{who}.{condition}."
    return sorted((key, flow) for key, flow in stored.flows.items() if key.startswith(prefix))


def _offered(stored: Stored, flows: Sequence[FlowResult]) -> float:
    """The messages the flows were to send at :data:`HZ`: an rclpy publisher beside a busy
    loop may send fewer than it was asked to."""
    return HZ * stored.numbers["seconds"] * len(flows)


def _span(stored: Stored, flows: Sequence[FlowResult]) -> str:
    shares = sorted(f.received / _offered(stored, [f]) for f in flows)
    return f"{shares[0]:.1%}" if len(shares) == 1 else f"{shares[0]:.1%}-{shares[-1]:.1%}"


def where_lost(stored: Stored, condition: str) -> str:
    """What the bridge received, dropped and published of what was sent, and what the
    subscriber took of what it published, over the condition's rounds."""
    sent = received = published = dropped = 0
    for key, flow in _rounds(stored, "bridge", condition):
        counted = stored_counters(stored.numbers, f"{key}.")
        if counted is None:
            return "the bridge's counters were not read"
        sent, received = sent + flow.sent, received + flow.received
        published, dropped = published + counted.published, dropped + counted.dropped
    reached = published + dropped
    return (
        f"of {sent} sent the bridge received {reached} ({reached / max(sent, 1):.1%}), dropped "
        f"{dropped} in its queue and published {published}; the subscriber took {received} of "
        f"those ({received / max(published, 1):.1%})"
    )


def goal_lines(stored: Stored | None) -> list[str]:
    """Per condition: the share of the offered messages delivered (every round pooled) against
    the goal and the same run's ceiling, and where the rest was lost."""
    if stored is None:
        return ["- not measured yet (`benchmarks.busy_neighbour`)"]
    lines = []
    for condition in CONDITIONS:
        bridge = [flow for _, flow in _rounds(stored, "bridge", condition)]
        if not bridge:
            continue
        ceiling_flows = [flow for _, flow in _rounds(stored, "ceiling", condition)]
        share = sum(f.received for f in bridge) / _offered(stored, bridge)
        ceiling_share = sum(f.received for f in ceiling_flows) / _offered(stored, ceiling_flows)
        ceiling_sent = sum(f.sent for f in ceiling_flows) / _offered(stored, ceiling_flows)
        gap = f"{100 * (GOAL_SHARE - share):.1f} points"
        lines.append(
            f"- Odometry offered at {HZ / 1000:g} kHz through one process, "
            f"{LABELS[condition]}: {min(share, 1.0):.1%} delivered (rounds "
            f"{_span(stored, bridge)}; goal >= {GOAL_SHARE:.0%}): "
            f"{verdict(share >= GOAL_SHARE, gap)}; the same run's rclpy publisher, asked for "
            f"the same rate, sent {min(ceiling_sent, 1.0):.1%} of it and delivered "
            f"{min(ceiling_share, 1.0):.1%} (rounds {_span(stored, ceiling_flows)}); "
            f"{where_lost(stored, condition)}"
        )
    return lines


def _row(key: str, flow: FlowResult, numbers: dict[str, float]) -> str:
    who, condition, index = key.split(".")
    counters = stored_counters(numbers, f"{key}.")
    counted = "-" if counters is None else counters.text()
    if flow.error:
        return f"| {LABELS[condition]} | {int(index) + 1} | {who} | failed: {flow.error} |||||"
    cpu = "-" if flow.cpu is None else f"{flow.cpu:.0f}%"
    return (
        f"| {LABELS[condition]} | {int(index) + 1} | {who} | {flow.received}/{flow.sent} "
        f"({flow.share:.1%}) | {counted} | {cpu} | {flow.pub_cpu or 0:.0f}% | "
        f"{flow.sub_cpu or 0:.0f}% | {flow.p99_us / 1000:.1f} ms |"
    )


def report(stored: Stored, command: str) -> str:
    def order(key: str) -> tuple[int, int, str]:
        who, condition, index = key.split(".")
        return CONDITIONS.index(condition), int(index), who

    rows = [_row(key, stored.flows[key], stored.numbers) for key in sorted(stored.flows, key=order)]
    return "\n".join(
        [
            "## Odometry at 20 kHz through one process, quiet and beside a busy loop (issue 36)",
            "",
            f"Command: `{command}`",
            "",
            (__doc__ or "").split("\n\n", 2)[2].strip(),
            "",
            "| machine | round | publisher | delivered/sent | bridge in / out / dropped "
            "| bridge CPU | publisher CPU | subscriber CPU | p99 latency |",
            "| --- | --- | --- | --- | --- | --- | --- | --- | --- |",
            *rows,
            "",
            *goal_lines(stored),
        ]
    )


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0] if __doc__ else None)
    parser.add_argument("--seconds", type=float, default=4.0)
    parser.add_argument("--rounds", type=int, default=2, help="rounds per condition")
    args = parser.parse_args(argv)
    load_before = os.getloadavg()[0]
    flows, numbers = measure(args.seconds, args.rounds)
    numbers["seconds"] = args.seconds
    store("busy_neighbour", flows, load_before, numbers)
    stored = load("busy_neighbour")  # what was just stored, with its commit and date
    if stored is None:
        msg = "benchmarks/results.json lost the figures just stored"
        raise RuntimeError(msg)
    command = (
        f".venv/bin/python -m benchmarks.busy_neighbour --seconds {args.seconds:g} "
        f"--rounds {args.rounds}"
    )
    write_section("busy_neighbour", report(stored, command))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

"""Bridge CPU per delivered message, per message type and direction, at fixed rates (issue 15).

Usage: ``.venv/bin/python -m benchmarks.costs [--seconds S]``; writes the report
``benchmarks/reports/costs.md`` and stores its flows for the headline. Every message must
arrive: histories of 1000 messages on the ROS ends and in the bridge's channels, as
``small_messages``' paced rows.
"""

from __future__ import annotations

import argparse
import os
import sys

from benchmarks.bridged import backend, ceilings, through_bridge
from benchmarks.harness import GZ_ENDS, PYTHON_THREADS, THREAD_GROUPS, FlowResult
from benchmarks.reference import CPU_PER_MESSAGE, QUOTED, cpu_goal_ms
from benchmarks.report import write_section
from benchmarks.results import store
from benchmarks.small_messages import PACED_DEPTH
from benchmarks.tables import SIZES, Row, verdict

GZ_TO_ROS = (
    ("odometry", 1000.0),
    ("odometry", 5000.0),
    ("twist", 1000.0),
    ("twist", 5000.0),
    ("tf20", 1000.0),
    ("imu", 1000.0),
)
ROS_TO_GZ = (("odometry", 1000.0), ("odometry", 5000.0), ("twist", 1000.0), ("twist", 5000.0))

#: The thread groups of the split columns, in order, and the column's title.
SPLIT_GROUPS = (PYTHON_THREADS, *(name for name, _ in THREAD_GROUPS))
SPLIT_COLUMN = "of which " + " / ".join(SPLIT_GROUPS) + " threads, ms"
HEADER = (
    "| message | direction | rate | delivered/sent | median ms | bridge CPU "
    f"| bridge CPU per message, ms | {SPLIT_COLUMN} | rclpy publisher per message, ms "
    f"| rclpy subscriber per message, ms | C++ bridge per message, ms ({QUOTED}) |\n"
    "|---|---|---|---|---|---|---|---|---|---|---|"
)


def per_message_ms(cpu: float | None, hz: float, result: FlowResult) -> float | None:
    """CPU time per delivered message (ms) of a process busy ``cpu`` % of a core while ``hz``
    messages a second were published, of which ``result.share`` arrived."""
    delivered_rate = hz * min(1.0, result.share)
    if cpu is None or delivered_rate <= 0 or result.error:
        return None
    return cpu / 100 / delivered_rate * 1000


def thread_split_ms(hz: float, result: FlowResult) -> dict[str, float] | None:
    """The bridge's CPU time per delivered message (ms) by thread group
    (:data:`~benchmarks.harness.THREAD_GROUPS`), where measured."""
    split: dict[str, float] = {}
    for group, cpu in (result.bridge_threads or {}).items():
        ms = per_message_ms(cpu, hz, result)
        if ms is None:
            return None
        split[group] = ms
    return split or None


def split_text(split: dict[str, float] | None) -> str:
    """``0.140 / 0.014 / 0.007``: the split in the order of :data:`SPLIT_GROUPS`."""
    if split is None:
        return "-"
    return " / ".join(f"{split.get(group, 0.0):.3f}" for group in SPLIT_GROUPS)


def flow_key(way: str, kind: str, hz: float) -> str:
    """The name a flow is stored under (``ceiling`` for the rclpy -> rclpy flows)."""
    return f"{way} {kind} {hz:g}"


def _ms(value: float | None) -> str:
    return "-" if value is None else f"{value:.3f}"


def _row(row: Row, way: str) -> str:
    result, ceiling = row.result, row.ceiling
    what = f"| {SIZES[row.kind]} | {way} | {row.hz:,.0f} Hz"
    if result.error:
        return f"{what} | failed: {result.error} |||||||"
    quoted = CPU_PER_MESSAGE.get((row.kind, way, row.hz))
    pub = sub = None
    if ceiling is not None:
        pub = per_message_ms(ceiling.pub_cpu, row.hz, ceiling)
        sub = per_message_ms(ceiling.sub_cpu, row.hz, ceiling)
    return (
        f"{what} | {result.received}/{result.sent} | {result.median_us / 1000:.2f} "
        f"| {result.cpu or 0:.0f}% | **{_ms(per_message_ms(result.cpu, row.hz, result))}** "
        f"| {split_text(thread_split_ms(row.hz, result))} "
        f"| {_ms(pub)} | {_ms(sub)} | {quoted.cpp_text() if quoted else '-'} |"
    )


def goal(row: Row, way: str) -> str | None:
    """The issue's verdict for a row that has a quoted C++ figure."""
    quoted = CPU_PER_MESSAGE.get((row.kind, way, row.hz))
    if quoted is None:
        return None
    what = f"- {SIZES[row.kind]} {way} at {row.hz:,.0f} Hz"
    bar = cpu_goal_ms(quoted)
    result = row.result
    cost = per_message_ms(result.cpu, row.hz, result)
    if cost is None:
        return f"{what}: not measured ({result.error or 'no CPU figure'})"
    all_there = result.received >= result.sent
    met = cost <= bar and all_there
    misses = []
    if cost > bar:
        misses.append(f"{cost - bar:.3f} ms per message ({cost / bar:.0%} of the bar)")
    if not all_there:
        misses.append(f"{result.sent - result.received} messages not delivered")
    return (
        f"{what}: {cost:.3f} ms per message, {result.received}/{result.sent} delivered; bar "
        f"{bar:.3f} ms (the C++ bridge: {quoted.cpp_text()}; {QUOTED}) — "
        f"{verdict(met, ' and '.join(misses))}"
    )


def run(seconds: float) -> tuple[str, dict[str, FlowResult]]:
    cases = tuple(dict.fromkeys(GZ_TO_ROS + ROS_TO_GZ))
    ceiling = ceilings(seconds, cases, depth=PACED_DEPTH)
    rows = through_bridge(
        seconds, backend("zeromq"), ceiling, GZ_TO_ROS, ROS_TO_GZ, depth=PACED_DEPTH
    )
    ways = ["GZ->ROS"] * len(GZ_TO_ROS) + ["ROS->GZ"] * len(ROS_TO_GZ)
    flows = {flow_key("ceiling", kind, hz): result for (kind, hz), result in ceiling.items()}
    flows |= {flow_key(way, r.kind, r.hz): r.result for way, r in zip(ways, rows, strict=True)}
    goals = [line for way, r in zip(ways, rows, strict=True) if (line := goal(r, way))]
    table = "\n".join(_row(row, way) for way, row in zip(ways, rows, strict=True))
    return (
        f"""## CPU per delivered message, per type (issue 15)

Command: `.venv/bin/python -m benchmarks.costs --seconds {seconds:g}`

One parameter_bridge (ZeroMQ) with a channel per message type and direction; each row
publishes at a fixed rate for {seconds:g} s, one row at a time. Every message must arrive:
histories of {PACED_DEPTH} messages on the ROS ends and in the bridge's channels (YAML
`publisher_queue` / `subscriber_queue`). **Bridge CPU per message** = the bridge process's CPU
time over the publishing window (/proc/<pid>/stat, all threads) / the messages delivered; the
split beside it is each thread's run time from the scheduler (/proc/<pid>/task/<tid>/schedstat)
over the same window, by thread name: libzmq's I/O thread (`ZMQbg/IO/0`), Fast DDS's threads
(`dds.*`), and the Python threads (the channel's reader, which receives, converts and publishes,
and the ROS executor on the main thread, which takes ROS messages and converts and publishes
them to Gazebo). The
ceiling columns are rclpy -> rclpy at the same rate and depth, in the same run: the CPU the
rclpy publisher process (stamping and publishing a message object) and the rclpy subscriber
process (taking and recording it) spend per message, what a ROS node in Python pays for each
end of the hop the bridge makes. {GZ_ENDS}

{HEADER}
{table}

Goals (issue 15: at most the C++ bridge's CPU per message, judged against the lower of its two
figures, with every message delivered):
{chr(10).join(goals)}
""",
        flows,
    )


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--seconds", type=float, default=4.0, help="publishing time per flow")
    args = parser.parse_args(argv)
    load = os.getloadavg()[0]
    section, flows = run(args.seconds)
    write_section("costs", section)
    store("costs", flows, load)
    return 0


if __name__ == "__main__":
    sys.exit(main())

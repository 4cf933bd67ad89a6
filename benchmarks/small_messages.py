"""Small messages at full rate through one channel each, both directions, beside the ceiling.

Usage: ``.venv/bin/python -m benchmarks.small_messages [--seconds S] [--no-zenoh]``; writes
the ``small_messages`` section of BENCHMARKS.md. Goal: >= 5,000 msg/s through one channel.
"""

from __future__ import annotations

import argparse
import sys

from benchmarks.bridged import backend, ceilings, through_bridge
from benchmarks.report import write_section
from benchmarks.tables import Row, table, verdict

CASES = (("twist", 0.0), ("odometry", 0.0), ("tf20", 0.0))
GOAL_RATE = 5000.0
#: The same channels with the publisher paced at the goal rate (ZeroMQ): does one channel
#: carry 5,000 msg/s when the bridge is not also receiving a flood it must drop?
PACED_CASES = (("twist", GOAL_RATE), ("odometry", GOAL_RATE))


def goal(row: Row) -> str:
    result = row.result
    what = f"{row.path}, {row.kind}"
    if result.error:
        return f"- {what} >= {GOAL_RATE:,.0f} msg/s: not measured ({result.error})"
    met = result.rate >= GOAL_RATE
    ceiling = f"; ceiling {row.ceiling.rate:,.0f} msg/s" if row.ceiling else ""
    return (
        f"- {what} >= {GOAL_RATE:,.0f} msg/s: {result.rate:,.0f}{ceiling} — "
        f"{verdict(met, f'{GOAL_RATE - result.rate:,.0f} msg/s')}"
    )


def paced(row: Row) -> str:
    result = row.result
    what = f"{row.path}, {row.kind} paced at {row.hz:,.0f} Hz"
    if result.error:
        return f"- {what}: not measured ({result.error})"
    return (
        f"- {what}: {result.received}/{result.sent} delivered ({result.share:.1%}), "
        f"{result.rate:,.0f} msg/s, median {result.median_us / 1000:.2f} ms"
    )


def run(seconds: float, zenoh: bool) -> str:
    ceiling = ceilings(seconds, CASES)
    ceiling_rows = [Row("ceiling: rclpy -> rclpy", k, hz, ceiling[k, hz]) for k, hz in CASES]
    rows = through_bridge(seconds, backend("zeromq"), ceiling, CASES, CASES)
    paced_rows = through_bridge(seconds, backend("zeromq"), ceiling, PACED_CASES, PACED_CASES)
    if zenoh:
        rows += through_bridge(seconds, backend("zenoh"), ceiling, CASES, CASES)
    flags = f" --seconds {seconds:g}" + ("" if zenoh else " --no-zenoh")
    return f"""## Small messages at full rate (Twist, Odometry, 20-transform TFMessage)

Command: `.venv/bin/python -m benchmarks.small_messages{flags}`

The publisher sends back to back for {seconds:g} s; one bridge process per backend with one
channel per message and direction. Latency is publish to callback (header stamp; Twist
carries it in `linear.x`). Reliable keep-last 10 on the ROS ends: a subscriber that falls
behind loses the oldest messages, so msg/s is what the subscriber received. Ceiling: rclpy
publisher -> rclpy subscriber with the bridge's settings, same run. Bridge CPU: % of one core.

{table(ceiling_rows + rows + paced_rows)}

Goal (>= {GOAL_RATE:,.0f} msg/s through one channel, both directions), judged flat out:
{chr(10).join(goal(row) for row in rows)}

Flat out, the publisher sends several times what any channel carries (a Python Gazebo
publisher reaches 80-90k msg/s), and the bridge receives and drops the excess on the same
2 cores. Paced at the goal rate instead (ZeroMQ):
{chr(10).join(paced(row) for row in paced_rows)}
"""


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--seconds", type=float, default=3.0, help="publishing time per flow")
    parser.add_argument("--no-zenoh", action="store_true", help="skip the Zenoh backend")
    args = parser.parse_args(argv)
    write_section("small_messages", run(args.seconds, not args.no_zenoh))
    return 0


if __name__ == "__main__":
    sys.exit(main())

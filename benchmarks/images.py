"""Large messages through the bridge (issues 5 and 6), side by side with the rclpy ceiling.

Usage: ``.venv/bin/python -m benchmarks.images [--seconds S] [--no-zenoh]``; writes the
report ``benchmarks/reports/images.md``. The ceiling is an rclpy publisher -> rclpy subscriber with
the same settings as the bridge (Fast DDS SHM profile, EventsExecutor, allocator tuning). The
Gazebo ends are those of ``benchmarks.harness.worker`` (the C++ Ignition Transport peer on
ZeroMQ, Python workers on Zenoh, on explicit loopback endpoints).
"""

from __future__ import annotations

import argparse
import importlib.util
import os
import sys

from benchmarks.bridged import (
    Ceilings,
    backend,
    bridge_process,
    ceilings,
    flow_through,
    through_bridge,
    unbridged,
)
from benchmarks.harness import (
    GZ_ENDS,
    Flow,
    FlowResult,
    bridge_argument,
    topic_name,
)
from benchmarks.report import write_section
from benchmarks.tables import Row, latency_goal, rate_goal, table

#: (kind, publishing rate) of every case; 0 = flat out.
CASES = (
    ("image640", 0.0),
    ("image640", 30.0),
    ("image1080", 0.0),
    ("image1080", 30.0),
    ("cloud1mb", 0.0),
)
ROS_TO_GZ_CASES = (("image640", 0.0), ("image1080", 0.0), ("image1080", 30.0), ("cloud1mb", 0.0))
ZENOH_CASES = (("image1080", 0.0), ("image1080", 30.0), ("cloud1mb", 0.0))


def through_image_bridge(seconds: float, ceiling: Ceilings) -> list[Row]:
    if importlib.util.find_spec("ros_gz_bridge_py.app.image_bridge") is None:
        return []
    which = backend("zeromq")
    topics = {kind: topic_name(f"ib_{kind}") for kind in ("image640", "image1080")}
    rows = []
    with bridge_process(list(topics.values()), which.bridge_env, "image_bridge") as bridge:
        for kind, hz in CASES:
            if kind in topics:
                result = flow_through(
                    Flow("gz-pub", "ros-sub", kind, seconds, hz), topics[kind], which, bridge
                )
                rows.append(
                    Row("GZ->ROS image_bridge (ZeroMQ)", kind, hz, result, ceiling[kind, hz])
                )
    return rows


#: Path label of the flows paced at the ceiling's own rate.
AT_CEILING = "GZ->ROS parameter_bridge (ZeroMQ), paced at the ceiling's rate"


def at_ceiling_rate(seconds: float, ceiling: Ceilings) -> list[Row]:
    """Images from Gazebo paced at the rate rclpy itself reached flat out.

    A Gazebo publisher, unlike an rclpy one, is never slowed down by its subscribers: flat out
    it sends many times what any bridge converts, and the bridge spends CPU receiving frames
    it then drops. Paced at the ceiling's rate, the question is only whether the bridge keeps up.
    """
    which = backend("zeromq")
    kinds = ("image640", "image1080")
    topics = {kind: topic_name(f"atc_{kind}") for kind in kinds}
    rows = []
    with bridge_process(
        [bridge_argument(topics[k], k, "gz2ros") for k in kinds], which.bridge_env
    ) as bridge:
        for kind in kinds:
            target = ceiling[kind, 0.0]
            if target.error or not target.rate:
                continue
            hz = round(target.rate)
            flow = Flow("gz-pub", "ros-sub", kind, seconds, hz)
            result = flow_through(flow, topics[kind], which, bridge)
            rows.append(Row(AT_CEILING, kind, hz, result, target))
    return rows


#: Path label of the flows through the Gazebo Transport hop alone.
HOP_ALONE = "Gazebo hop alone (ZeroMQ): publisher -> subscriber, no bridge, no ROS"
HOP_CASES = (("image640", 0.0), ("image1080", 0.0), ("image1080", 30.0))
Hops = dict[tuple[str, float], FlowResult]


def hops_alone(seconds: float) -> Hops:
    """The Gazebo publisher straight to a Gazebo subscriber: what the ZeroMQ hop that every
    bridged frame also takes costs on this machine, without the bridge or ROS."""
    return unbridged(seconds, HOP_CASES, ("gz-pub", "gz-sub"), "hop alone")


def hop_note(row: Row, hops: Hops) -> str:
    """What the Gazebo hop alone did in the case of ``row`` (ZeroMQ rows only)."""
    hop = hops.get((row.kind, 0.0 if row.path == AT_CEILING else row.hz))
    if "ZeroMQ" not in row.path or hop is None or hop.error or row.ceiling is None:
        return ""
    if row.hz == 30 and row.path != AT_CEILING:
        both = (hop.median_us + row.ceiling.median_us) / 1000
        own = row.result.median_us / 1000 - both
        return (
            f"; the Gazebo hop alone takes {hop.median_us / 1000:.2f} ms (median), so the two "
            f"hops a bridged frame takes add up to {both:.2f} ms; the bridge's own share is "
            f"{own:+.2f} ms"
        )
    share = hop.rate / row.ceiling.rate if row.ceiling.rate else 0.0
    return (
        f"; the Gazebo hop alone, flat out, carried {hop.rate:,.0f} msg/s: {share:.0%} of the "
        "ceiling before any bridge work"
    )


def goals(rows: list[Row], hops: Hops) -> list[str]:
    lines = []
    for row in rows:
        if not row.path.startswith("GZ->ROS"):
            continue
        if row.kind in {"image640", "image1080"} and (row.hz == 0 or row.path == AT_CEILING):
            lines.append(rate_goal(row, 0.9) + hop_note(row, hops))
        if row.kind == "image1080" and row.hz == 30:
            lines.append(latency_goal(row, 2.0) + hop_note(row, hops))
    return lines


def markdown(rows: list[Row], ceiling: Ceilings, hops: Hops, seconds: float, command: str) -> str:
    ceiling_rows = [
        Row("ceiling: rclpy -> rclpy", k, hz, result) for (k, hz), result in ceiling.items()
    ]
    hop_rows = [
        Row(HOP_ALONE, k, hz, result, ceiling.get((k, hz))) for (k, hz), result in hops.items()
    ]
    return f"""## Images and point clouds through the bridge (issues 5, 6)

Command: `{command}`

Each row: one publisher process, the bridge process (one per backend, every channel of the
table configured at once) and one subscriber process, {seconds:g} s of publishing. Latency is
publish time (CLOCK_MONOTONIC in the header stamp) to the subscriber's callback. The
**ceiling** is rclpy publisher -> rclpy subscriber, no bridge, with the bridge's own speed
settings (Fast DDS 64 MB SHM profile, EventsExecutor, allocator tuning); "vs ceiling" is
msg/s against the ceiling row of the same message and rate, measured in the same run. Bridge
CPU is % of one core from /proc/<pid>/stat over the publishing window. With 2 cores the
bridge path runs three busy processes where the ceiling runs two, so flat-out rows are bound
by the machine as much as by the bridge. ROS QoS: reliable, keep-last 10 (the bridge's
default) on both ends; the Gazebo publisher's ZeroMQ high-water mark is 20 messages. A
Gazebo publisher is not slowed down by its subscribers as an rclpy one is (DDS reliability):
flat out it sends several times what the bridge converts, and the bridge receives, then
drops, the rest. The rows "paced at the ceiling's rate" publish from Gazebo at the msg/s the
ceiling reached flat out, to show whether the bridge keeps up with what rclpy itself does.
The rows "Gazebo hop alone" send the same messages from the Gazebo publisher straight to a
Gazebo subscriber: the ZeroMQ hop every bridged frame takes before the bridge, whose rate
and latency no bridge can beat. {GZ_ENDS}

{table(ceiling_rows + hop_rows + rows)}

Goals (issue 5: 1080p GZ->ROS >= 90% of the ceiling's msg/s, 1080p@30 Hz median within 2 ms
of the ceiling's, 640x480 >= 90%):
{chr(10).join(goals(rows, hops))}
"""


def run(seconds: float, zenoh: bool) -> str:
    all_cases = tuple(dict.fromkeys(CASES + ROS_TO_GZ_CASES))
    ceiling = ceilings(seconds, all_cases)
    hops = hops_alone(seconds)
    rows = through_bridge(seconds, backend("zeromq"), ceiling, CASES, ROS_TO_GZ_CASES)
    rows += through_image_bridge(seconds, ceiling)
    rows += at_ceiling_rate(seconds, ceiling)
    if zenoh:
        rows += through_bridge(seconds, backend("zenoh"), ceiling, ZENOH_CASES, ZENOH_CASES)
    flags = f" --seconds {seconds:g}" + ("" if zenoh else " --no-zenoh")
    command = f".venv/bin/python -m benchmarks.images{flags}"
    return markdown(rows, ceiling, hops, seconds, command)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--seconds", type=float, default=3.0, help="publishing time per flow")
    parser.add_argument("--no-zenoh", action="store_true", help="skip the Zenoh backend")
    args = parser.parse_args(argv)
    os.environ.setdefault("PYTHONUNBUFFERED", "1")
    write_section("images", run(args.seconds, not args.no_zenoh))
    return 0


if __name__ == "__main__":
    sys.exit(main())

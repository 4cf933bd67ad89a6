"""``/clock`` at 1 kHz through a bridge that a 1080p image stream saturates (issue 3).

Usage: ``.venv/bin/python -m benchmarks.starvation [--seconds S]``; writes the ``starvation``
section of BENCHMARKS.md. One parameter_bridge carries ``/clock`` (gz.msgs.Clock ->
rosgraph_msgs/Clock) and a 1920x1080 Image topic, both Gazebo -> ROS. The clock is measured
alone, then while a Gazebo publisher floods the image topic. Goal: >= 95% of clock messages
arrive under load.
"""

from __future__ import annotations

import argparse
import sys
import threading
import time

from benchmarks.bridged import backend, bridge_process, flow_through
from benchmarks.harness import Flow, FlowResult, bridge_argument, topic_name
from benchmarks.report import write_section
from benchmarks.tables import Row, table, verdict

CLOCK_HZ = 1000.0
GOAL_SHARE = 0.95
#: Seconds the image flood runs before and after the clock phase.
MARGIN = 3.0


#: A paced flood: above what the bridge converts per second (about 150 1080p frames on the
#: bulk path), so the bridge is saturated and drops frames, without the publisher process
#: taking a whole core of its own.
PACED_FLOOD_HZ = 200.0


def clock_under_flood(
    seconds: float, flood_hz: float
) -> tuple[FlowResult, FlowResult, FlowResult | None]:
    """/clock alone, then under a 1080p flood at ``flood_hz`` (0 = flat out), one bridge."""
    which = backend("zeromq")
    clock_topic, image_topic = topic_name("clock"), topic_name("starve_image")
    arguments = [bridge_argument(clock_topic, "clock", "gz2ros")]
    arguments.append(bridge_argument(image_topic, "image1080", "gz2ros"))
    clock = Flow("gz-pub", "ros-sub", "clock", seconds, CLOCK_HZ)
    flood: list[FlowResult] = []
    with bridge_process(arguments, which.bridge_env) as bridge:
        alone = flow_through(clock, clock_topic, which, bridge)
        image = Flow("gz-pub", "ros-sub", "image1080", seconds + 20 + 2 * MARGIN, flood_hz)
        flooding = threading.Thread(
            target=lambda: flood.append(flow_through(image, image_topic, which, bridge))
        )
        flooding.start()
        time.sleep(MARGIN + 8)  # the image flow's processes start, match and begin publishing
        loaded = flow_through(clock, clock_topic, which, bridge)
        flooding.join()
    return alone, loaded, flood[0] if flood else None


def run(seconds: float) -> str:
    path = "GZ->ROS parameter_bridge (ZeroMQ)"
    rows: list[Row] = []
    goals: list[str] = []
    for flood_hz, label in ((PACED_FLOOD_HZ, f"{PACED_FLOOD_HZ:g} Hz"), (0.0, "flat out")):
        alone, loaded, flood = clock_under_flood(seconds, flood_hz)
        rows.append(Row(f"{path}, /clock alone", "clock", CLOCK_HZ, alone))
        rows.append(Row(f"{path}, /clock under images {label}", "clock", CLOCK_HZ, loaded))
        if flood is not None:
            rows.append(Row(f"{path}, the image flood ({label})", "image1080", flood_hz, flood))
        share = loaded.share
        met = share >= GOAL_SHARE and not loaded.error
        goals.append(
            f"- images {label}: {loaded.received}/{loaded.sent} = {share:.1%}, p99 latency "
            f"{loaded.p99_us / 1000:.2f} ms (alone: {alone.share:.1%}, p99 "
            f"{alone.p99_us / 1000:.2f} ms) — "
            + verdict(met, f"{(GOAL_SHARE - share) * 100:.1f} points")
        )
    goal_lines = "\n".join(goals)
    return f"""## /clock under a saturating image stream (issue 3)

Command: `.venv/bin/python -m benchmarks.starvation --seconds {seconds:g}`

One bridge process with two Gazebo -> ROS channels: `/clock` (a Python Gazebo publisher at
{CLOCK_HZ:g} Hz, `sim` = CLOCK_MONOTONIC) and a 1920x1080 rgb8 Image topic. First the clock
alone ({seconds:g} s), then the clock again while another publisher sends images (the flood
starts ~{MARGIN + 8:g} s before the clock phase and outlasts it). Two floods, each with a fresh
bridge: paced at {PACED_FLOOD_HZ:g} Hz, more than the bridge converts (it saturates the bridge
and drops frames at its bounded queue), and flat out, where the publisher process also takes a
whole core, so the bridge and the ROS subscriber share the other one. Each channel has its own
delivery thread and bounded queue in the bridge. Bridge CPU: % of one core over the window.

{table(rows)}

Goal (>= {GOAL_SHARE:.0%} of /clock messages arrive while images saturate the bridge):
{goal_lines}
"""


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--seconds", type=float, default=5.0, help="clock publishing time")
    args = parser.parse_args(argv)
    write_section("starvation", run(args.seconds))
    return 0


if __name__ == "__main__":
    sys.exit(main())

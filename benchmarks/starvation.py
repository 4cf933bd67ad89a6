"""``/clock`` at 1 kHz through a bridge that a 1080p image stream saturates (issue 3).

Usage: ``.venv/bin/python -m benchmarks.starvation [--seconds S]``; writes the ``starvation``
section of BENCHMARKS.md. One parameter_bridge carries ``/clock`` (gz.msgs.Clock ->
rosgraph_msgs/Clock) and a 1920x1080 Image topic, both Gazebo -> ROS. The clock is measured
alone, then while a Gazebo publisher floods the image topic. Goal: >= 95% of clock messages
arrive under load.
"""

from __future__ import annotations

import argparse
import os
import signal
import sys
import threading
import time
from dataclasses import dataclass

from benchmarks.bridged import Backend, backend, bridge_process, flow_through
from benchmarks.harness import GZ_ENDS, Flow, FlowResult, bridge_argument, topic_name
from benchmarks.report import write_section
from benchmarks.tables import Row, table, verdict
from tests.gzpeer import PeerProcess

CLOCK_HZ = 1000.0
GOAL_SHARE = 0.95
#: Seconds the image flood runs before and after the clock phase.
MARGIN = 3.0


#: A paced flood: above what the bridge converts per second (about 150 1080p frames on the
#: bulk path), so the bridge is saturated and drops frames, without the publisher process
#: taking a whole core of its own.
PACED_FLOOD_HZ = 200.0


#: History depth of the second clock subscriber: enough for a 100 ms scheduling gap at 1 kHz.
DEEP_DEPTH = 100


@dataclass(frozen=True)
class ClockRun:
    """One clock measurement, and how many of its messages the bridge itself published."""

    result: FlowResult
    forwarded: int | None


@dataclass(frozen=True)
class FloodRun:
    alone: ClockRun
    loaded: ClockRun
    loaded_deep: ClockRun
    flood: FlowResult | None


def published_count(bridge: PeerProcess | None, topic: str) -> int | None:
    """The OUT counter of the bridge's channel on ``topic``, from its SIGUSR1 status table."""
    if bridge is None:
        return None
    before = len(bridge.output().splitlines())
    deadline = time.monotonic() + 5
    while time.monotonic() < deadline:
        # Until the bridge spins, SIGUSR1 is ignored: ask again until a table comes.
        os.kill(bridge.pid, signal.SIGUSR1)
        time.sleep(0.3)
        for line in bridge.output().splitlines()[before:]:
            fields = line.split()
            if len(fields) >= 10 and fields[1] == "GZ->ROS" and fields[2] == topic:
                return int(fields[6])
    return None


def clock_through(bridge: PeerProcess | None, clock: Flow, topic: str, which: Backend) -> ClockRun:
    first = published_count(bridge, topic)
    result = flow_through(clock, topic, which, bridge)
    last = published_count(bridge, topic)
    forwarded = None if first is None or last is None else last - first
    return ClockRun(result, forwarded)


def clock_under_flood(seconds: float, flood_hz: float) -> FloodRun:
    """/clock alone, then twice under a 1080p flood at ``flood_hz`` (0 = flat out): with a
    subscriber of depth 10 and of depth :data:`DEEP_DEPTH`; one bridge."""
    which = backend("zeromq")
    clock_topic, image_topic = topic_name("clock"), topic_name("starve_image")
    arguments = [bridge_argument(clock_topic, "clock", "gz2ros")]
    arguments.append(bridge_argument(image_topic, "image1080", "gz2ros"))
    clock = Flow("gz-pub", "ros-sub", "clock", seconds, CLOCK_HZ)
    deep = Flow("gz-pub", "ros-sub", "clock", seconds, CLOCK_HZ, depth=DEEP_DEPTH)
    flood: list[FlowResult] = []
    with bridge_process(arguments, which.bridge_env) as bridge:
        alone = clock_through(bridge, clock, clock_topic, which)
        image = Flow("gz-pub", "ros-sub", "image1080", 2 * seconds + 40 + 2 * MARGIN, flood_hz)
        flooding = threading.Thread(
            target=lambda: flood.append(flow_through(image, image_topic, which, bridge))
        )
        flooding.start()
        time.sleep(MARGIN + 8)  # the image flow's processes start, match and begin publishing
        loaded = clock_through(bridge, clock, clock_topic, which)
        loaded_deep = clock_through(bridge, deep, clock_topic, which)
        flooding.join()
    return FloodRun(alone, loaded, loaded_deep, flood[0] if flood else None)


def _forwarded(run: ClockRun) -> str:
    if run.forwarded is None or not run.result.sent:
        return "bridge counters unavailable"
    return f"the bridge published {run.forwarded}/{run.result.sent}"


def run(seconds: float) -> str:
    path = "GZ->ROS parameter_bridge (ZeroMQ)"
    rows: list[Row] = []
    goals: list[str] = []
    for flood_hz, label in ((PACED_FLOOD_HZ, f"{PACED_FLOOD_HZ:g} Hz"), (0.0, "flat out")):
        got = clock_under_flood(seconds, flood_hz)
        rows.append(Row(f"{path}, /clock alone", "clock", CLOCK_HZ, got.alone.result))
        for clock_run, depth in ((got.loaded, 10), (got.loaded_deep, DEEP_DEPTH)):
            name = f"{path}, /clock under images {label}, subscriber depth {depth}"
            rows.append(Row(name, "clock", CLOCK_HZ, clock_run.result))
        if got.flood is not None:
            rows.append(Row(f"{path}, the image flood ({label})", "image1080", flood_hz, got.flood))
        for clock_run, depth in ((got.loaded, 10), (got.loaded_deep, DEEP_DEPTH)):
            loaded = clock_run.result
            met = loaded.share >= GOAL_SHARE and not loaded.error
            goals.append(
                f"- images {label}, subscriber depth {depth}: {loaded.received}/{loaded.sent} = "
                f"{loaded.share:.1%} arrived ({_forwarded(clock_run)}), p99 latency "
                f"{loaded.p99_us / 1000:.2f} ms (alone: {got.alone.result.share:.1%}, p99 "
                f"{got.alone.result.p99_us / 1000:.2f} ms) — "
                + verdict(met, f"{(GOAL_SHARE - loaded.share) * 100:.1f} points")
            )
    goal_lines = "\n".join(goals)
    return f"""## /clock under a saturating image stream (issue 3)

Command: `.venv/bin/python -m benchmarks.starvation --seconds {seconds:g}`

One bridge process with two Gazebo -> ROS channels: `/clock` (a Gazebo publisher at
{CLOCK_HZ:g} Hz, `sim` = CLOCK_MONOTONIC) and a 1920x1080 rgb8 Image topic. First the clock
alone ({seconds:g} s), then the clock twice while another publisher sends images (the flood
starts ~{MARGIN + 8:g} s before the first clock phase and outlasts the second): once to an
rclpy subscriber of depth 10 (the bridge's default QoS), once of depth {DEEP_DEPTH}. Two
floods, each with a fresh bridge: paced at {PACED_FLOOD_HZ:g} Hz, more than the bridge converts
(it saturates the bridge and drops frames at its bounded queue), and flat out, where the
publisher process also takes a whole core. Each channel has its own delivery thread and
bounded queue in the bridge; the image channel takes the bulk path, whose DDS write runs
with the GIL released. "The bridge published" is the clock channel's own counter (SIGUSR1
status table) over the phase: what the bridge did, apart from what the subscriber process,
sharing 2 cores with four other busy processes, managed to take before its history
overflowed. Bridge CPU: % of one core over the window. {GZ_ENDS}

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

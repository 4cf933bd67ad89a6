"""The bridge's memory under a long 1080p flood, and with a ROS subscriber slower than Gazebo.

Usage: ``.venv/bin/python -m benchmarks.memory [--flood-seconds S] [--slow-seconds S]``;
writes the report ``benchmarks/reports/memory.md``. Goals: a full-rate 1080p Gazebo -> ROS flood
grows the bridge's RSS by < 50 MB (from a warm-up to the end), and a subscriber that takes
longer per image than the publisher makes nothing queue without bound (RSS flat, excess dropped).
"""

from __future__ import annotations

import argparse
import statistics
import sys
import threading
import time
from dataclasses import dataclass, field

from benchmarks.bridged import backend, bridge_process, flow_through
from benchmarks.harness import GZ_ENDS, Flow, FlowResult, bridge_argument, topic_name
from benchmarks.report import write_section
from benchmarks.tables import Row, table, verdict
from testing.procstat import rss_mb

GOAL_MB = 50.0
#: Seconds of flooding before the RSS baseline is taken (buffers and queues fill first).
WARM_UP = 5.0
SAMPLE_PERIOD = 0.5
SLOW_MS = 100.0


@dataclass
class RssSampler:
    """Samples a process's RSS every SAMPLE_PERIOD seconds on a thread, from :meth:`start`."""

    pid: int
    samples: list[tuple[float, float]] = field(default_factory=list)
    _stop: threading.Event = field(default_factory=threading.Event)

    def start(self) -> None:
        threading.Thread(target=self._run, daemon=True).start()

    def _run(self) -> None:
        begin = time.monotonic()
        while not self._stop.wait(SAMPLE_PERIOD):
            try:
                self.samples.append((time.monotonic() - begin, rss_mb(self.pid)))
            except OSError:
                return

    def stop(self) -> None:
        self._stop.set()

    def trajectory(self, points: int = 8) -> str:
        """RSS at evenly spaced times, to tell a plateau (bounded) from a climb (a leak)."""
        if not self.samples:
            return "no samples"
        step = max(1, len(self.samples) // points)
        picked = [*self.samples[::step], self.samples[-1]]
        return ", ".join(f"{at:.0f} s: {mb:.0f}" for at, mb in dict(picked).items())

    def summary(self) -> tuple[float, float, float]:
        """(median RSS of the first third after the warm-up, the peak, median of the last
        third) in MB. Single samples swing by ~100 MB as 6 MB buffers come and go; a leak
        moves the medians, a swing does not."""
        warm = [mb for at, mb in self.samples if at >= WARM_UP] or [0.0]
        third = max(1, len(warm) // 3)
        return statistics.median(warm[:third]), max(warm), statistics.median(warm[-third:])


@dataclass(frozen=True)
class Phase:
    name: str
    result: FlowResult
    rss: tuple[float, float, float]
    trajectory: str = ""

    @property
    def growth(self) -> float:
        return self.rss[2] - self.rss[0]


def measure(name: str, flow: Flow, topic: str) -> Phase:
    which = backend("zeromq")
    with bridge_process([bridge_argument(topic, flow.kind, "gz2ros")], which.bridge_env) as bridge:
        if bridge is None:
            return Phase(name, FlowResult(0, 0, 0, 0, 0, None, "bridge did not start"), (0, 0, 0))
        sampler = RssSampler(bridge.pid)
        result = flow_through(flow, topic, which, bridge, during=sampler.start)
        sampler.stop()
    print(f"{name}: RSS {sampler.trajectory()}", file=sys.stderr, flush=True)
    return Phase(name, result, sampler.summary(), sampler.trajectory())


def goal(phase: Phase) -> str:
    start, peak, last = phase.rss
    met = phase.growth < GOAL_MB and not phase.result.error
    dropped = phase.result.sent - phase.result.received
    return (
        f"- {phase.name}: RSS median {start:.0f} MB over the first third after {WARM_UP:g} s, "
        f"peak {peak:.0f} MB, median {last:.0f} MB over the last third: "
        f"growth {phase.growth:+.1f} MB (< {GOAL_MB:g} MB) — "
        f"{verdict(met, f'{phase.growth - GOAL_MB:.1f} MB')}; {dropped} of "
        f"{phase.result.sent} images not delivered (dropped). RSS MB over time: "
        f"{phase.trajectory}"
    )


def run(flood_seconds: float, slow_seconds: float) -> str:
    flood = measure(
        "full-rate flood", Flow("gz-pub", "ros-sub", "image1080", flood_seconds), topic_name("mem")
    )
    slow_flow = Flow("gz-pub", "ros-sub", "image1080", slow_seconds, slow_ms=SLOW_MS)
    slow = measure(f"subscriber taking {SLOW_MS:g} ms per image", slow_flow, topic_name("slow"))
    path = "GZ->ROS parameter_bridge (ZeroMQ)"
    rows = [Row(f"{path}, {p.name}", "image1080", 0.0, p.result) for p in (flood, slow)]
    return f"""## Bridge memory under a 1080p flood and a slow subscriber

Command: `.venv/bin/python -m benchmarks.memory --flood-seconds {flood_seconds:g} \
--slow-seconds {slow_seconds:g}`

A Gazebo publisher sends 1920x1080 rgb8 images back to back through a fresh
parameter_bridge (Gazebo -> ROS) to an rclpy subscriber: first for {flood_seconds:g} s, then
for {slow_seconds:g} s to a subscriber that sleeps {SLOW_MS:g} ms in each callback. The
bridge's RSS (/proc/<pid>/status VmRSS) is sampled every {SAMPLE_PERIOD:g} s from {WARM_UP:g} s
into the flood; growth is the median of the last third of the samples minus the median of the
first third (single samples swing by ~100 MB as 6 MB frames are received, queued, copied and
freed, so first-versus-last-sample differences measure the swing, not a leak; the peak and the
trajectory are shown too). Images the bridge
cannot pass on are dropped (its per-channel queue drops the oldest; the ROS publisher keeps the
last 10). {GZ_ENDS}

{table(rows)}

Goals (growth < {GOAL_MB:g} MB; with the slow subscriber RSS stays flat, drops counted):
{goal(flood)}
{goal(slow)}
"""


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--flood-seconds", type=float, default=60.0)
    parser.add_argument("--slow-seconds", type=float, default=15.0)
    args = parser.parse_args(argv)
    write_section("memory", run(args.flood_seconds, args.slow_seconds))
    return 0


if __name__ == "__main__":
    sys.exit(main())

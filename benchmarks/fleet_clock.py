"""Where a fleet's ``/clock`` is lost: in the bridge, or between its ROS writer and the
subscriber (issue 36 item 5).

Usage: ``.venv/bin/python -m benchmarks.fleet_clock [--robots 50] [--seconds 20] [--rounds 3]``.

Each round is a bridge round of ``benchmarks.fleet`` (the same simulator, bridge and subscriber
processes, ``/clock`` in a process of its own, depth 10): over the window, the bridge's own
``/clock`` counters (its status table, SIGUSR1: taken from its socket, published, dropped in its
queue) against what the subscriber counted, and against the schedule (1 kHz).
"""

from __future__ import annotations

import argparse
import os
import re
import time
from collections.abc import Sequence
from dataclasses import dataclass

from benchmarks.fleet_rounds import start_bridged
from benchmarks.harness import stop_all
from benchmarks.report import write_section
from testing import fleet_sim
from testing.e2e_harness import status_rows
from testing.run_env import run_env

#: A status row's IN, OUT, ERRORS and DROPPED columns (core/status.py's table).
_ROW = re.compile(rf"GZ->ROS\s+{fleet_sim.CLOCK_TOPIC}\s+\S+\s+\w+\s+(\d+)\s+(\d+)\s+\d+\s+(\d+)")


@dataclass(frozen=True)
class ClockRound:
    seconds: float
    #: In the window: messages the bridge took, published, dropped; the subscriber's count.
    taken: int
    published: int
    dropped: int
    delivered: int
    load: float

    def share(self, count: int) -> str:
        return f"{100 * count / (fleet_sim.CLOCK_HZ * self.seconds):.1f}%"


def _counters(rows: list[str]) -> tuple[int, int, int]:
    """The newest /clock row's counters (the bridge's output holds every table it printed)."""
    for row in reversed(rows):
        found = _ROW.search(row)
        if found:
            taken, published, dropped = (int(value) for value in found.groups())
            return taken, published, dropped
    msg = f"no /clock row in the bridge's status table: {rows}"
    raise RuntimeError(msg)


def clock_round(robots: int, seconds: float) -> ClockRound:
    """One bridge round of ``robots``: /clock counted at the bridge and at its subscriber."""
    load = os.getloadavg()[0]
    fleet = start_bridged(robots, run_env())
    try:
        before = _counters(status_rows(fleet.bridge, [fleet_sim.CLOCK_TOPIC]))
        counted = fleet.subscribers.counts()[fleet_sim.CLOCK_TOPIC]
        began = time.monotonic()
        time.sleep(seconds)
        after = _counters(status_rows(fleet.bridge, [fleet_sim.CLOCK_TOPIC]))
        delivered = fleet.subscribers.counts()[fleet_sim.CLOCK_TOPIC] - counted
        window = time.monotonic() - began
        fleet.finish()
    finally:
        stop_all()
    taken, published, dropped = (a - b for a, b in zip(after, before, strict=True))
    return ClockRound(window, taken, published, dropped, delivered, load)


def report(robots: int, rounds: list[ClockRound], command: str) -> str:
    lines = [
        "## Where a fleet's /clock is lost (issue 36 item 5)",
        "",
        f"Command: `{command}`",
        "",
        (__doc__ or "").split("\n\n", 2)[2].strip(),
        "",
        f"Fleet of {robots} robots; each window about {rounds[0].seconds:.0f} s (1-minute load "
        "before each round in the last column).",
        "",
        "| round | bridge took | bridge published | dropped in the bridge | subscriber got "
        "| load |",
        "| --- | --- | --- | --- | --- | --- |",
    ]
    for index, r in enumerate(rounds, 1):
        lines.append(
            f"| {index} | {r.taken} ({r.share(r.taken)}) | {r.published} "
            f"({r.share(r.published)}) | {r.dropped} | {r.delivered} ({r.share(r.delivered)}) "
            f"| {r.load:.1f} |"
        )
    lost_in_bridge = sum(r.taken - r.published + r.dropped for r in rounds)
    lines += [
        "",
        f"Lost in the bridge over all rounds: {lost_in_bridge} messages; what the subscriber "
        "missed of what the bridge published was lost between the bridge's ROS writer and the "
        "subscriber's callback (its process's share of the 2 cores, its keep-last history).",
    ]
    return "\n".join(lines)


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0] if __doc__ else None)
    parser.add_argument("--robots", type=int, default=50)
    parser.add_argument("--seconds", type=float, default=20.0)
    parser.add_argument("--rounds", type=int, default=3)
    args = parser.parse_args(argv)
    rounds = []
    for _ in range(args.rounds):
        rounds.append(clock_round(args.robots, args.seconds))
        print(rounds[-1], flush=True)
    command = (
        f".venv/bin/python -m benchmarks.fleet_clock --robots {args.robots} "
        f"--seconds {args.seconds:g} --rounds {args.rounds}"
    )
    write_section("fleet_clock", report(args.robots, rounds, command))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

"""``make bench``: every benchmark in one go, each bounded, each rewriting its report.

Usage: ``.venv/bin/python -m benchmarks.run [--quick] [--only NAME ...]``. The full run takes
about 30 minutes on 2 cores; ``--quick`` shortens every phase (a smoke run, numbers noisier).
Each module writes its own report; a module that fails is reported and the others still run.
Last, the headline is rewritten from the figures stored by ``sustained``, ``costs``,
``starvation``, ``fleet`` and ``busy_neighbour`` (this run's, or their last run's when they
were not run), and its plots drawn.
The Gazebo ends of ZeroMQ flows are the C++ peer on the real ign-transport 11 (built on first
use, see ``testing/gzpeer.py``); ``BENCH_GZ_END=python`` puts our Python workers there instead.
"""

from __future__ import annotations

import argparse
import os
import sys
import time
import traceback
from collections.abc import Callable

from benchmarks import (
    busy_neighbour,
    conversion,
    costs,
    discovery,
    first_call,
    fleet,
    fleet_clock,
    fleet_memory,
    headline,
    images,
    instructions,
    memory,
    native_plane,
    small_messages,
    startup,
    starvation,
    sustained,
    transport,
)
from benchmarks.harness import stop_all
from benchmarks.report import write_section
from ros_gz_bridge_py.ros.speed import PROFILE

#: The offered 1080p rates of a quick run.
QUICK_RATES = (30.0, 90.0, 150.0)


def steps(quick: bool) -> dict[str, Callable[[], int]]:
    """Each benchmark with the phase lengths of a full (or quick) run."""
    flow = 1.5 if quick else 2.5
    rates = QUICK_RATES if quick else sustained.RATES
    return {
        "conversion": lambda: conversion.main(["--seconds", "0.2" if quick else "0.5"]),
        "transport": lambda: transport.main(["--seconds", "1" if quick else "2"]),
        "images": lambda: images.main(["--seconds", str(flow)]),
        "sustained": lambda: sustained.main(
            ["--seconds", "1.5" if quick else "5", "--rates", *(f"{hz:g}" for hz in rates)]
        ),
        "instructions": lambda: instructions.main(["--messages", "50" if quick else "200"]),
        "small_messages": lambda: small_messages.main(["--seconds", str(flow)]),
        "costs": lambda: costs.main(["--seconds", "1.5" if quick else "3"]),
        "starvation": lambda: starvation.main(["--seconds", "3" if quick else "5"]),
        "native_plane": lambda: native_plane.main(
            [
                *("--seconds", "1" if quick else "2"),
                *("--workload-seconds", "3" if quick else "10"),
                *("--workload-rounds", "1" if quick else "3"),
                *("--clock-seconds", "2" if quick else "5"),
            ]
        ),
        "discovery": lambda: discovery.main(
            ["--idle", "5" if quick else "10"] + (["--counts", "10", "100"] if quick else [])
        ),
        "startup": lambda: startup.main(["--rounds", "3" if quick else "5"]),
        "first_call": lambda: first_call.main(["--runs", "5" if quick else "10"]),
        "fleet": lambda: fleet.main(
            [
                *("--robots", "10", "25", "50"),
                *("--seconds", "5" if quick else "20"),
                *("--rounds", "1" if quick else "2"),
                *("--idle-seconds", "5" if quick else "20"),
            ]
        ),
        "fleet_clock": lambda: fleet_clock.main(
            [
                *("--robots", "50"),
                *("--seconds", "5" if quick else "20"),
                *("--rounds", "1" if quick else "3"),
            ]
        ),
        "fleet_memory": lambda: fleet_memory.main(
            [
                *("--robots", "50"),
                *("--seconds", "10" if quick else "60"),
                *("--rounds", "1" if quick else "2"),
            ]
        ),
        "busy_neighbour": lambda: busy_neighbour.main(
            ["--seconds", "2" if quick else "4", "--rounds", "1" if quick else "2"]
        ),
        "memory": lambda: memory.main(
            ["--flood-seconds", "15" if quick else "60", "--slow-seconds", "8" if quick else "15"]
        ),
    }


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--quick", action="store_true", help="short phases (smoke run)")
    parser.add_argument("--only", nargs="+", choices=list(steps(False)), help="run only these")
    args = parser.parse_args(argv)
    chosen = steps(args.quick)
    names = args.only or list(chosen)
    load, start, lines = os.getloadavg()[0], time.monotonic(), []
    for name in names:
        began = time.monotonic()
        print(f"== {name}", file=sys.stderr, flush=True)
        try:
            failed = chosen[name]()
            outcome = f"**not run** (exit status {failed}, see the console)" if failed else "done"
        except Exception:
            traceback.print_exc()
            outcome = "**failed** (see the console output); its report is from an earlier run"
        finally:
            stop_all()
        lines.append(f"- `{name}`: {outcome} in {time.monotonic() - began:.0f} s")
    headline.main([])  # from the figures just measured and the stored ones of the others
    flags = (" --quick" if args.quick else "") + (f" --only {' '.join(names)}" if args.only else "")
    write_section(
        "run",
        f"""## This run

Command: `make bench` (= `.venv/bin/python -m benchmarks.run{flags}` with the loopback
environment). Total {time.monotonic() - start:.0f} s; 1-minute load average before the run
{load:.2f}, after {os.getloadavg()[0]:.2f} (other work on the machine skews every number).
Every ROS process (bridge, ceiling, workers) uses the bridge's speed settings: the Fast DDS
profile `{PROFILE.name}` (64 MB shared-memory segment), the EventsExecutor and the glibc
allocator tuning.

{chr(10).join(lines)}
""",
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())

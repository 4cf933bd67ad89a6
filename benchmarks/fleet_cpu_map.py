"""Where a fleet message's CPU goes in the bridge: per thread, per stage of the message path, and
what issue 36 lists as candidates, per delivered message (issue 36 item 1).

Usage: ``.venv/bin/python -m benchmarks.fleet_cpu_map [--robots 10 25] [--seconds 20]
[--syscall-seconds 10] [--profile-seconds 10] [--hz 999]``.

Per fleet size: the fleet of ``benchmarks.fleet`` as users run it (the C++ simulator, one
``parameter_bridge``, the subscriber processes; ``fleet_rounds.start_bridged``), then three
windows one after the other, each with the messages the subscribers took in it (both
directions; ``cmd_vel`` as a share of what the subscribers sent, as in ``benchmarks.fleet``):

1. a clean window (nothing attached): every thread's run time and context switches from
   ``/proc/<pid>/task/<tid>`` (``bridge_threads``), by role from the thread's OS name;
2. system calls per thread, counted in the kernel (``perf stat``, ``perf_syscalls``);
3. ``perf record`` of every thread with DWARF call stacks (``perf_profile``): each thread
   role's samples sorted into stages by the libraries' entry points and into cross-cuts.

Then the same for the same run's rclpy ceiling of ``benchmarks.fleet`` (one rclpy process in
the bridge's place, ``fleet_rounds.start_ceiling``), so that each stage of the bridge stands
beside what plain rclpy spends on it; which of the two goes first alternates from one size to
the next. Everything is read from outside the process, by thread name, ``/proc`` and perf, so
the module runs unchanged on any arrangement of the bridge's loops. A stage's µs per message is
its share of its role's samples times that role's µs per message in the clean window (perf's
own cost does not enter it). The report, ``benchmarks/reports/fleet_cpu_map.md``, is
written beside the single-topic breakdown (``costs``) and the figures stored in
``benchmarks/results.json``.
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from collections import Counter, defaultdict
from collections.abc import Callable
from pathlib import Path

from benchmarks import perf_profile, perf_syscalls
from benchmarks.bridge_threads import by_role, read_threads, role_of
from benchmarks.fleet_cpu_figures import CpuMap, Delivered, numbers
from benchmarks.fleet_cpu_report import section
from benchmarks.fleet_rounds import BridgedFleet, CeilingFleet, start_bridged, start_ceiling
from benchmarks.harness import ROOT, stop_all
from benchmarks.report import write_section
from benchmarks.results import store
from testing.procstat import cpu_seconds
from testing.run_env import run_env

#: Where perf's files go.
WORK = ROOT / ".build" / "fleet_cpu_map"


RunningFleet = BridgedFleet | CeilingFleet


def _delivered(fleet: RunningFleet, run: Callable[[], None]) -> Delivered:
    """The messages the subscribers took while ``run`` ran."""
    before = fleet.subscribers.counts()
    began = time.monotonic()
    run()
    seconds = time.monotonic() - began
    after = fleet.subscribers.counts()
    gz = sum(after[t] - before[t] for t in after if t != "cmd_vel")
    return Delivered(gz, after["cmd_vel"] - before["cmd_vel"], seconds)


def measure(robots: int, args: argparse.Namespace, ceiling: bool) -> CpuMap:
    """One fleet size through the bridge, or the ceiling's one rclpy process in its place
    (module docstring)."""
    side = "ceiling" if ceiling else "bridge"
    print(f"== CPU map of a fleet of {robots}, {side}", file=sys.stderr, flush=True)
    result = CpuMap(robots, os.getloadavg()[0], ceiling=ceiling)
    profile_file = WORK / f"{side}_{robots}.perf"
    profile_file.unlink(missing_ok=True)
    try:
        fleet: RunningFleet = (start_ceiling if ceiling else start_bridged)(robots, run_env())
        pid = fleet.measured.pid
        readings = [read_threads(pid)]
        cpu = [cpu_seconds(pid)]

        def clean() -> None:
            time.sleep(args.seconds)
            readings.append(read_threads(pid))
            cpu.append(cpu_seconds(pid))

        result.clean = _delivered(fleet, clean)
        result.cpu_percent = 100 * (cpu[1] - cpu[0]) / result.clean.seconds
        result.roles = by_role(pid, readings[0], readings[1])
        result.names = frozenset(reading.comm for reading in readings[1].values())
        result.process = readings[1][pid].comm
        _count_syscalls(fleet, result, args)
        _record_profile(fleet, result, args, profile_file)
        result.commanded = fleet.finish()[0]
    finally:
        stop_all()
    if profile_file.exists():
        profiles: dict[str, perf_profile.Profile] = defaultdict(perf_profile.Profile)
        for sample in perf_profile.samples(profile_file):
            profiles[role_of(sample.comm, sample.tid, pid, result.process)].add(sample)
        result.profiles = dict(profiles)
    print(f"{result.total_us:.1f} µs per delivered message", file=sys.stderr, flush=True)
    return result


def _count_syscalls(fleet: RunningFleet, result: CpuMap, args: argparse.Namespace) -> None:
    why = perf_syscalls.missing()
    if why or args.syscall_seconds <= 0:
        result.notes.append(f"system calls not counted: {why or 'asked not to'}")
        return
    pid = fleet.measured.pid
    counted: dict[tuple[str, int], dict[str, int]] = {}
    path = WORK / f"syscalls_{'ceiling' if result.ceiling else 'bridge'}_{result.robots}.txt"

    def count() -> None:
        counted.update(perf_syscalls.count(pid, args.syscall_seconds, path))

    result.syscall_window = _delivered(fleet, count)
    by_role_calls: dict[str, Counter[str]] = defaultdict(Counter)
    for (comm, tid), calls in counted.items():
        by_role_calls[role_of(comm, tid, pid, result.process)].update(calls)
    result.syscalls = dict(by_role_calls)


def _record_profile(
    fleet: RunningFleet, result: CpuMap, args: argparse.Namespace, path: Path
) -> None:
    why = perf_profile.missing()
    if why or args.profile_seconds <= 0:
        result.notes.append(f"no profile: {why or 'asked not to'}")
        return
    pid = fleet.measured.pid
    result.profile_window = _delivered(
        fleet, lambda: perf_profile.record(pid, args.profile_seconds, args.hz, path)
    )


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--robots", type=int, nargs="+", default=[10, 25])
    parser.add_argument("--seconds", type=float, default=20.0, help="the clean window")
    parser.add_argument("--syscall-seconds", type=float, default=10.0, help="0: none")
    parser.add_argument("--profile-seconds", type=float, default=10.0, help="0: none")
    parser.add_argument("--hz", type=int, default=999, help="perf's samples per CPU second")
    args = parser.parse_args(argv)
    load = os.getloadavg()[0]
    # Per size the bridge and the ceiling, the first of them swapped from one size to the next.
    maps = [
        measure(robots, args, ceiling)
        for n, robots in enumerate(args.robots)
        for ceiling in ((False, True) if n % 2 == 0 else (True, False))
    ]
    store("fleet_cpu_map", {}, load, numbers(maps))
    write_section("fleet_cpu_map", section(maps, args, (load, os.getloadavg()[0])))
    return 0


if __name__ == "__main__":
    sys.exit(main())

"""The ROS side of a fleet round: the subscriber processes of ``benchmarks.fleet_ros`` (``/clock``
alone, at most ten robots a process), started together and read as one."""

from __future__ import annotations

import json
import signal
import sys
import time
from collections.abc import Mapping
from dataclasses import dataclass

from benchmarks.fleet_goals import FLOW_TIMEOUT
from benchmarks.fleet_ros import parts
from benchmarks.harness import FlowFailure
from testing.gzpeer import PeerProcess, start_process, wait_for_line
from testing.procstat import cpu_seconds

#: Longest wait for a subscriber process to say READY.
READY_TIMEOUT = 60.0


def counts_of(process: PeerProcess) -> dict[str, int]:
    """A ``benchmarks.fleet_ros`` process's counts so far (it prints them on SIGUSR1)."""
    process.send_signal(signal.SIGUSR1)
    counts: dict[str, int] = json.loads(wait_for_line(process, r"^COUNTS (.*)$", 10)[1])
    return counts


@dataclass
class Subscribers:
    """The subscriber processes of one fleet, in the order of :func:`parts`."""

    processes: list[PeerProcess]

    @classmethod
    def start(cls, robots: int, env: Mapping[str, str]) -> Subscribers:
        """Start every process of the layout at once, then wait for each to be READY."""
        command = [sys.executable, "-m", "benchmarks.fleet_ros", "sub"]
        started = cls([start_process([*command, *part], env) for part in parts(robots)])
        for process in started.processes:
            wait_for_line(process, r"^READY$", READY_TIMEOUT)
        return started

    @property
    def pids(self) -> list[int]:
        return [process.pid for process in self.processes]

    def counts(self) -> dict[str, int]:
        """Every topic's count so far, and ``cmd_vel``: the commands all of them sent."""
        merged = {"cmd_vel": 0}
        for process in self.processes:
            counts = counts_of(process)
            merged["cmd_vel"] += counts.pop("cmd_vel")
            merged |= counts
        return merged

    def wait_flowing(self) -> tuple[float | None, tuple[str, ...]]:
        """When (wall clock) every topic of every process had brought a message; if that does
        not happen within :data:`FLOW_TIMEOUT`, None and the topics that brought nothing (the
        run goes on: the delivered shares then show them)."""
        deadline = time.monotonic() + FLOW_TIMEOUT
        latest = 0.0
        try:
            for process in self.processes:
                left = max(deadline - time.monotonic(), 0.1)
                latest = max(latest, float(wait_for_line(process, r"^ALL_FLOWING (\S+)$", left)[1]))
        except FlowFailure:
            counts = self.counts()
            return None, tuple(t for t, n in counts.items() if not n and t != "cmd_vel")
        return latest, ()

    def cpu_seconds(self) -> float:
        """CPU time of all of them so far."""
        return sum(cpu_seconds(pid) for pid in self.pids)

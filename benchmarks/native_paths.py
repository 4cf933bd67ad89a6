"""What the native plane's experiments share: a bridge on either path (native, or Python with
``ROS_GZ_BRIDGE_NATIVE=off``), and what they read while it runs: its status table's counters,
its threads' CPU, the machine's busy time."""

from __future__ import annotations

import os
import signal
import threading
import time
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

from benchmarks.bridged import Backend
from benchmarks.harness import PYTHON_THREADS, THREAD_GROUPS
from ros_gz_bridge_py.app.settings import NATIVE_ENV
from testing.gzpeer import PeerProcess
from testing.procstat import CLOCK_TICKS
from testing.run_env import run_env

#: The bridge environment of each path, over :func:`~testing.run_env.run_env`'s.
PATHS = {"native": {}, "Python": {NATIVE_ENV: "off"}}
SPLIT = " / ".join([PYTHON_THREADS, *(name for name, _ in THREAD_GROUPS)])


def path_backend(path: str) -> Backend:
    """ZeroMQ, the bridge on ``path`` (the Gazebo and ROS ends as every benchmark's)."""
    env = run_env()
    bridge_env = {key: value for key, value in env.items() if key != NATIVE_ENV}
    return Backend(f"ZeroMQ, {path} path", bridge_env | PATHS[path], env)


# --- the bridge's own counters ------------------------------------------------------------------


@dataclass(frozen=True)
class Counters:
    """A GZ->ROS channel's IN, OUT and DROPPED, and its PATH, from the status table."""

    received: int
    published: int
    dropped: int
    path: str

    def since(self, before: Counters) -> Counters:
        return Counters(
            self.received - before.received,
            self.published - before.published,
            self.dropped - before.dropped,
            self.path,
        )

    def text(self) -> str:
        return f"{self.received} / {self.published} / {self.dropped}"

    def numbers(self, prefix: str) -> dict[str, float]:
        """The three counts as ``results.store`` keeps them: ``prefix`` + in, out, dropped."""
        return {
            f"{prefix}in": self.received,
            f"{prefix}out": self.published,
            f"{prefix}dropped": self.dropped,
        }


def stored_counters(numbers: Mapping[str, float], prefix: str) -> Counters | None:
    """The counts :meth:`Counters.numbers` gave under ``prefix`` (the path is not stored)."""
    try:
        return Counters(
            int(numbers[f"{prefix}in"]),
            int(numbers[f"{prefix}out"]),
            int(numbers[f"{prefix}dropped"]),
            "",
        )
    except KeyError:
        return None


def counters(bridge: PeerProcess | None, topics: Sequence[str]) -> dict[str, Counters]:
    """The status row of the bridge's GZ->ROS channel of each of ``topics`` (ROS names);
    the topics whose row did not come within 5 s are missing."""
    if bridge is None:
        return {}
    wanted = {topic.lstrip("/"): topic for topic in topics}
    before = len(bridge.output().splitlines())
    found: dict[str, Counters] = {}
    deadline = time.monotonic() + 5
    while time.monotonic() < deadline and len(found) < len(wanted):
        # Until the bridge spins, SIGUSR1 is ignored: ask again until a table comes.
        os.kill(bridge.pid, signal.SIGUSR1)
        time.sleep(0.3)
        for line in bridge.output().splitlines()[before:]:
            fields = line.split()
            if len(fields) >= 12 and fields[1] == "GZ->ROS" and fields[2].lstrip("/") in wanted:
                found[wanted[fields[2].lstrip("/")]] = Counters(
                    int(fields[5]), int(fields[6]), int(fields[8]), fields[-1]
                )
    return found


def counted_since(
    before: dict[str, Counters], after: dict[str, Counters], topic: str
) -> Counters | None:
    if topic not in before or topic not in after:
        return None
    return after[topic].since(before[topic])


def threads_cell(groups: dict[str, float] | None) -> str:
    """A bridge's CPU by thread group, % of one core (``SPLIT``'s order)."""
    if not groups:
        return "-"
    return " / ".join(f"{groups.get(name, 0.0):.0f}%" for name in SPLIT.split(" / "))


def thread_seconds(pid: int) -> dict[str, float]:
    """CPU seconds of each live thread of ``pid`` (scheduler run time), by ``name/tid``."""
    seconds = {}
    for tid in os.listdir(f"/proc/{pid}/task"):
        try:
            with open(f"/proc/{pid}/task/{tid}/comm", encoding="utf-8") as comm:
                name = comm.read().strip()
            with open(f"/proc/{pid}/task/{tid}/schedstat", encoding="ascii") as schedstat:
                seconds[f"{name}/{tid}"] = int(schedstat.read().split()[0]) / 1e9
        except (OSError, ValueError, IndexError):  # the thread ended meanwhile
            continue
    return seconds


def busiest(before: dict[str, float], after: dict[str, float], wall: float, count: int = 5) -> str:
    """The ``count`` threads that ran most between two :func:`thread_seconds`, % of a core."""
    used = {name: (after[name] - before.get(name, 0.0)) / wall for name in after}
    top = sorted(used.items(), key=lambda item: -item[1])[:count]
    return ", ".join(f"`{name}` {100 * share:.1f}%" for name, share in top)


def idle_seconds() -> float:
    """Idle (and I/O wait) time of all the machine's CPUs so far (/proc/stat). Busy time is
    the wall time of all CPUs less this: /proc/stat's own busy columns are sampled at the
    tick and miss most of the short bursts of a process woken 1000 times a second (measured:
    4.8% of the machine for a process that ran 6.2% by its own run time), its idle time is
    kept exactly."""
    with open("/proc/stat", encoding="ascii") as stat:
        ticks = stat.readline().split()[1:]
    return (int(ticks[3]) + int(ticks[4])) / CLOCK_TICKS


class MachineWindow:
    """How busy all the machine's CPUs were, % of all of them, between :meth:`begin` and
    :meth:`end`; ``MachineWindow(seconds).begin`` ends by itself after ``seconds`` (a flow's
    ``during``, which runs once publishing started)."""

    def __init__(self, seconds: float | None = None) -> None:
        self._seconds = seconds
        self._start = (0.0, 0.0)
        self.percent: float | None = None

    def begin(self) -> None:
        self._start = (time.monotonic(), idle_seconds())
        if self._seconds is not None:
            timer = threading.Timer(self._seconds, self.end)
            timer.daemon = True
            timer.start()

    def end(self) -> None:
        wall = (time.monotonic() - self._start[0]) * (os.cpu_count() or 1)
        self.percent = 100 * (1 - (idle_seconds() - self._start[1]) / max(wall, 1e-9))


def cpu_cell(value: float | None) -> str:
    return "-" if value is None else f"{value:.0f}%"

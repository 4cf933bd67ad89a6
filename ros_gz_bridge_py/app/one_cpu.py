"""Keep the bridge's threads on one CPU while its load is light (docs/environment.md §2).

A bridge of many small topics hands every message from thread to thread: the libzmq I/O thread
wakes the native loop, the loop writes to Fast DDS, whose threads wake for the acknowledgements.
Spread over CPUs, each hand-off is a wake-up across CPUs, dear on a virtual machine. With every
thread on one CPU a fleet of 10 robots cost the bridge about a quarter less per message, at no
loss of delivery; but one CPU is a ceiling, and a neighbour on that CPU makes the bridge wait.

So ``parameter_bridge`` (not ``image_bridge``, all images, nor a
:class:`~ros_gz_bridge_py.core.bridge.Bridge` embedded in your own program) looks at its
process once a second: while it carries no image or point cloud channel,
and uses at most :data:`PIN_LOAD` of a core, all its threads share the least busy CPU it may
run on; past :data:`RELEASE_LOAD`, when that CPU is full while another has room (a neighbour
the kernel cannot move, one pinned there too), or when a bulk channel comes, they get back
every CPU they had, and stay spread for a hold that doubles at each release. (How long its
threads wait for a CPU does not tell: about as long as they run, pinned or not, quiet machine
or busy, in the fleet runs of docs/environment.md §2.) ``ROS_GZ_BRIDGE_ONE_CPU=off`` leaves
the threads alone, as does a process already limited to one CPU.

:class:`OneCpuPolicy` decides from :class:`Sample` figures (no I/O, tested alone);
:class:`OneCpu` reads them from ``/proc`` and applies the decisions.
"""

from __future__ import annotations

import os
import time
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from ros_gz_bridge_py.ros.runtime import steady_clock

#: Seconds between two looks at the process.
PERIOD = 1.0
#: Pin only at or below this load (cores the process used over the last period).
PIN_LOAD = 0.5
#: Spread again above this load: one CPU is near full.
RELEASE_LOAD = 0.7
#: Spread again when the pinned CPU is at least this busy (a share of its time)...
FULL_CPU = 0.95
#: ...while another CPU the process may use is at most this busy.
ROOMY_CPU = 0.75
#: Seconds the threads stay spread after the first release; doubled at each release after.
FIRST_HOLD = 30.0
#: The longest hold.
LONGEST_HOLD = 600.0


@dataclass(frozen=True)
class Sample:
    """What the process looks like at one moment; the policy compares two of them."""

    #: Monotonic seconds.
    time: float
    #: CPU seconds of every thread of the process so far.
    cpu: float
    #: Busy and total ticks of each CPU it may run on, so far (``/proc/stat``).
    cpu_ticks: Mapping[int, tuple[int, int]]
    #: A channel of images or point clouds exists.
    bulk: bool


@dataclass(frozen=True)
class Move:
    """Put every thread on ``cpu``, or with None give them back the CPUs they started with;
    ``why`` says so in the log."""

    cpu: int | None
    why: str


class OneCpuPolicy:
    """When to pin and where; fed one :class:`Sample` a period, it answers a move or None."""

    def __init__(self) -> None:
        self.pinned: int | None = None
        self._last: Sample | None = None
        self._hold_until = 0.0
        self._hold = FIRST_HOLD

    def step(self, now: Sample) -> Move | None:
        last, self._last = self._last, now
        if last is None or now.time <= last.time:
            return None
        seconds = now.time - last.time
        load = (now.cpu - last.cpu) / seconds
        shares = _busy_shares(last.cpu_ticks, now.cpu_ticks)
        figures = f"the bridge used {load:.0%} of a core"
        if self.pinned is not None:
            why = _release_reason(now.bulk, load, self.pinned, shares)
            if why is None:
                return None
            self.pinned = None
            self._hold_until = now.time + self._hold
            why = f"{why} ({figures}); spread for {self._hold:.0f} s"
            self._hold = min(self._hold * 2, LONGEST_HOLD)
            return Move(None, why)
        if now.time < self._hold_until or now.bulk or load > PIN_LOAD or len(shares) < 2:
            return None
        cpu = min(shares, key=lambda cpu: (shares[cpu], cpu))
        self.pinned = cpu
        return Move(cpu, f"a light load ({figures})")


def _release_reason(
    bulk: bool, load: float, pinned: int, shares: Mapping[int, float]
) -> str | None:
    if bulk:
        return "an image or point cloud channel"
    if load > RELEASE_LOAD:
        return "a heavy load"
    others = [share for cpu, share in shares.items() if cpu != pinned]
    busy = shares.get(pinned, 0.0)
    if busy >= FULL_CPU and others and min(others) <= ROOMY_CPU:
        return f"CPU {pinned} {busy:.0%} busy, mostly with other work, another {min(others):.0%}"
    return None


def _busy_shares(
    before: Mapping[int, tuple[int, int]], after: Mapping[int, tuple[int, int]]
) -> dict[int, float]:
    """The share of its time each CPU of both samples was busy between them."""
    return {
        cpu: (busy - before[cpu][0]) / (total - before[cpu][1])
        for cpu, (busy, total) in after.items()
        if cpu in before and total > before[cpu][1]
    }


def cpu_ticks(stat: str, cpus: Iterable[int]) -> dict[int, tuple[int, int]]:
    """(busy, total) ticks of each of ``cpus`` in the text of ``/proc/stat``."""
    wanted = set(cpus)
    ticks = {}
    for line in stat.splitlines():
        name, _, rest = line.partition(" ")
        if not name.startswith("cpu") or not name[3:].isdigit() or int(name[3:]) not in wanted:
            continue
        # user nice system idle iowait irq softirq steal; guest time (the columns after) is
        # counted in user and nice already
        values = [int(value) for value in rest.split()[:8]]
        idle = sum(values[3:5])  # idle, iowait
        ticks[int(name[3:])] = (sum(values) - idle, sum(values))
    return ticks


class OneCpu:
    """The policy applied to this process, on a steady timer of ``ros_node``."""

    def __init__(
        self,
        ros_node: Any,
        bulk: Callable[[], bool],
        period: float = PERIOD,
    ) -> None:
        self._logger = ros_node.get_logger()
        self._bulk = bulk
        self._allowed = frozenset(os.sched_getaffinity(0))
        self._policy = OneCpuPolicy()
        self._placed: set[int] = set()
        self._timer = ros_node.create_timer(period, self.look, clock=steady_clock())
        self._node = ros_node

    def look(self) -> None:
        """Sample the process and apply the policy's move (the timer's callback)."""
        try:
            move = self._policy.step(self.sample())
            if move is not None:
                self._placed.clear()
                if move.cpu is None:
                    self._place(self._allowed, set())
            if self._policy.pinned is not None:  # threads started since are placed too
                self._place(frozenset({self._policy.pinned}), self._placed)
            if move is not None:
                where = "every CPU again" if move.cpu is None else f"CPU {move.cpu}"
                self._logger.info(f"bridge threads on {where}: {move.why}")
        except OSError as err:  # /proc unreadable here: leave the threads as they are
            self._logger.warning(f"cannot place the bridge's threads ({err}); leaving them")
            self.close()

    def sample(self) -> Sample:
        times = os.times()
        return Sample(
            time=time.monotonic(),
            cpu=times.user + times.system,
            cpu_ticks=cpu_ticks(Path("/proc/stat").read_text(), self._allowed),
            bulk=self._bulk(),
        )

    def _place(self, cpus: frozenset[int], done: set[int]) -> None:
        """Give every thread not in ``done`` the CPUs ``cpus``; add it to ``done``."""
        for tid in map(int, os.listdir("/proc/self/task")):
            if tid in done:
                continue
            try:
                os.sched_setaffinity(tid, cpus)
            except OSError:  # ended meanwhile
                continue
            done.add(tid)

    def close(self) -> None:
        self._node.destroy_timer(self._timer)


def start_one_cpu(ros_node: Any, bulk: Callable[[], bool], enabled: bool) -> OneCpu | None:
    """The placement ``parameter_bridge`` runs, or None when switched off or when there is only
    one CPU to run on."""
    if not enabled or len(os.sched_getaffinity(0)) < 2:
        return None
    return OneCpu(ros_node, bulk)

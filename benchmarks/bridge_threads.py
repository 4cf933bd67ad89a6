"""The threads of a running bridge process by role, read from outside through ``/proc``.

A thread's role comes from its OS name (``/proc/<pid>/task/<tid>/comm``, 15 characters), which
the bridge gives its own threads (docs/threads.md) and libzmq and Fast DDS give theirs; the
names of both the two-loop data plane (``gz-native``, ``ros-loop``, ``gz-fallback``) and the
unified one (``native-gz``, ``native-ros``, ``native-fallback``) are known, so the same readings
hold before and after that change. A Python thread the bridge does not name keeps the process's
name; the main thread (the rclpy executor) is the one whose id is the process's. Per thread: its
run time (``schedstat``, nanoseconds) and its context switches (``status``: voluntary ones are
the thread going to sleep, so each is a wake-up to come; involuntary ones are preemptions).
"""

from __future__ import annotations

import os
import re
from collections.abc import Mapping
from dataclasses import dataclass

#: The start of a libzmq thread's name: after a number where its context has one
#: (``6/ZMQbg/IO/0``, the bulk path's; ``transport/zmq/bulk_context.py``).
LIBZMQ_THREAD = r"(\d+/)?ZMQbg/"
#: Roles by OS thread name, first match wins; the order is the order of the tables.
ROLES = (
    ("Gazebo -> ROS loop", re.compile(r"^(gz-native|native-gz)$")),
    ("ROS -> Gazebo loop", re.compile(r"^(ros-loop|native-ros)$")),
    ("fallback (Python)", re.compile(r"^(gz-fallback|native-fallback|ros-fallback)$")),
    ("topic readers (Python, gz-sub)", re.compile(r"^gz-sub")),
    ("libzmq I/O", re.compile(rf"^{LIBZMQ_THREAD}IO")),
    ("libzmq other", re.compile(rf"^{LIBZMQ_THREAD}")),
    ("Fast DDS events", re.compile(r"^dds\.ev")),
    ("Fast DDS shared-memory receive", re.compile(r"^dds\.shm\.\d")),
    ("Fast DDS UDP receive", re.compile(r"^dds\.udp")),
    ("Fast DDS other", re.compile(r"^dds\.")),
)
#: The context switch counts of ``/proc/<pid>/task/<tid>/status``.
SWITCHES = ("voluntary_ctxt_switches", "nonvoluntary_ctxt_switches")
MAIN = "main thread (Python)"
OTHER_PYTHON = "other unnamed threads (Python)"
#: Every role, in table order.
ORDER = (*(name for name, _ in ROLES[:4]), MAIN, OTHER_PYTHON, *(name for name, _ in ROLES[4:]))


def role_of(comm: str, tid: int, pid: int, process: str | None = None) -> str:
    """The role of thread ``tid`` of process ``pid`` named ``comm``; a name no role knows is
    an unnamed Python thread's where it is the process's name (``process``, the main thread's)
    or not known, else a role of its own (``other: <name>``, digits as N)."""
    if tid == pid:
        return MAIN
    known = next((name for name, pattern in ROLES if pattern.search(comm)), None)
    if known is not None:
        return known
    if process is None or comm == process:
        return OTHER_PYTHON
    return "other: " + re.sub(r"\d+", "N", comm)


@dataclass(frozen=True)
class Reading:
    """One thread at one moment."""

    comm: str
    run_ns: int
    voluntary: int
    involuntary: int


def read_threads(pid: int) -> dict[int, Reading]:
    """Every live thread of ``pid`` by id (a thread that ends while being read is left out)."""
    readings = {}
    for entry in os.listdir(f"/proc/{pid}/task"):
        base = f"/proc/{pid}/task/{entry}"
        try:
            with open(f"{base}/comm", encoding="utf-8", errors="replace") as comm:
                name = comm.read().strip()
            with open(f"{base}/schedstat", encoding="ascii") as schedstat:
                run_ns = int(schedstat.read().split()[0])
            with open(f"{base}/status", encoding="utf-8", errors="replace") as status:
                switches = dict(
                    line.split(":", 1) for line in status if line.split(":")[0] in SWITCHES
                )
        except (OSError, ValueError, IndexError):
            continue
        readings[int(entry)] = Reading(
            name,
            run_ns,
            *(int(switches.get(name, "0")) for name in SWITCHES),
        )
    return readings


@dataclass
class RoleUse:
    """What the threads of one role did over a window."""

    threads: int = 0
    cpu_s: float = 0.0
    voluntary: int = 0
    involuntary: int = 0
    names: frozenset[str] = frozenset()


def by_role(
    pid: int, before: Mapping[int, Reading], after: Mapping[int, Reading]
) -> dict[str, RoleUse]:
    """What each role's threads did between two readings of ``pid`` (a thread born in the
    window counts from zero; one that ended in it is missing from ``after`` and left out)."""
    roles = {name: RoleUse() for name in ORDER}
    process = after[pid].comm if pid in after else None
    for tid, now in after.items():
        then = before.get(tid, Reading(now.comm, 0, 0, 0))
        use = roles.setdefault(role_of(now.comm, tid, pid, process), RoleUse())
        use.threads += 1
        use.cpu_s += (now.run_ns - then.run_ns) / 1e9
        use.voluntary += now.voluntary - then.voluntary
        use.involuntary += now.involuntary - then.involuntary
        use.names = use.names | {re.sub(r"\d+", "N", now.comm)}
    return roles

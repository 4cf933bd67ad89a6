"""System calls per thread of a running process, counted in the kernel by ``perf stat``.

``perf stat --per-thread -e syscalls:sys_enter_<name>,...,raw_syscalls:sys_enter -p PID``
counts each listed call and every call at all per thread, for a bounded window; the kernel only
increments counters, so the process runs almost as without it (unlike ``strace``, which stops
the thread on every call, or ``perf trace``, which copies every call out). Calls not in
:data:`NAMED` are counted together as ``other``.
"""

from __future__ import annotations

import shutil
import subprocess
from collections import defaultdict
from pathlib import Path

#: The calls counted by name: those a bridge's loops, libzmq and Fast DDS make on the message
#: path (waiting, eventfd and socket reads and writes, locks, libzmq's fork check), and the
#: common others.
NAMED = (
    "futex", "getpid", "poll", "ppoll", "epoll_wait", "epoll_pwait", "read", "write", "readv",
    "writev", "recvfrom", "recvmsg", "recvmmsg", "sendto", "sendmsg", "sendmmsg", "epoll_ctl",
    "clock_nanosleep", "nanosleep", "sched_yield", "mmap", "munmap", "madvise", "brk",
    "getsockopt", "setsockopt", "ioctl", "gettid", "openat", "close", "select", "pselect6",
)  # fmt: skip
OTHER = "other"
#: Where the kernel lists its syscall tracepoints.
TRACEFS = (
    Path("/sys/kernel/tracing/events/syscalls"),
    Path("/sys/kernel/debug/tracing/events/syscalls"),
)


def missing() -> str | None:
    """Why the counts cannot be taken here, or None."""
    if shutil.which("perf") is None:
        return "perf is not installed"
    if not any(path.is_dir() for path in TRACEFS):
        return (
            "the kernel's syscall tracepoints are not visible (tracefs; as root: "
            "mount -t tracefs nodev /sys/kernel/tracing)"
        )
    return None


def _events() -> tuple[list[str], list[str]]:
    """The named calls this kernel has a tracepoint for, and perf's events for them."""
    folder = next(path for path in TRACEFS if path.is_dir())
    names = [name for name in NAMED if (folder / f"sys_enter_{name}").is_dir()]
    return names, [*(f"syscalls:sys_enter_{name}" for name in names), "raw_syscalls:sys_enter"]


def count(pid: int, seconds: float, output: Path) -> dict[tuple[str, int], dict[str, int]]:
    """Calls per thread (its name and id) of ``pid`` over ``seconds``, by name
    (:data:`NAMED`, ``other``)."""
    _, events = _events()
    output.parent.mkdir(parents=True, exist_ok=True)
    subprocess.run(
        [
            "perf", "stat", "--per-thread", "-x", ";", "-e", ",".join(events), "-p", str(pid),
            "-o", str(output), "--", "sleep", f"{seconds:g}",
        ],
        check=True, capture_output=True, timeout=seconds + 60,
    )  # fmt: skip
    return parse(output.read_text(encoding="utf-8"))


def parse(text: str) -> dict[tuple[str, int], dict[str, int]]:
    """``perf stat --per-thread -x ';'`` output as calls per thread (name, id) and call; the
    total (``raw_syscalls:sys_enter``) less the named ones is ``other``."""
    calls: dict[tuple[str, int], dict[str, int]] = defaultdict(dict)
    totals: dict[tuple[str, int], int] = {}
    for line in text.splitlines():
        fields = line.split(";")
        if line.startswith("#") or len(fields) < 4 or "-" not in fields[0]:
            continue
        comm, tid = fields[0].rsplit("-", 1)
        thread = (comm, int(tid))
        value = int(fields[1]) if fields[1].isdigit() else 0
        event = fields[3]
        if event == "raw_syscalls:sys_enter":
            totals[thread] = value
        elif event.startswith("syscalls:sys_enter_"):
            calls[thread][event.removeprefix("syscalls:sys_enter_")] = value
    for thread, total in totals.items():
        calls[thread][OTHER] = max(total - sum(calls[thread].values()), 0)
    return {thread: {name: n for name, n in named.items() if n} for thread, named in calls.items()}

"""Readings of a running process from ``/proc`` (Linux): CPU time, resident memory, threads,
TCP sockets."""

from __future__ import annotations

import os
import subprocess
import threading
import time
from dataclasses import dataclass
from pathlib import Path

#: Clock ticks per second of ``/proc/<pid>/stat``.
CLOCK_TICKS = os.sysconf("SC_CLK_TCK")
MB = 1024 * 1024


def cpu_seconds(pid: int) -> float:
    """User + system CPU time of process ``pid`` (all its threads)."""
    with open(f"/proc/{pid}/stat", encoding="ascii") as stat:
        fields = stat.read().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / CLOCK_TICKS


def rss_bytes(pid: int, field: str = "VmRSS") -> int:
    """The resident set size (VmRSS) of process ``pid``, or another memory ``field`` of its
    status (``VmHWM``: the peak resident set size so far); 0 where it has none (a zombie)."""
    with open(f"/proc/{pid}/status", encoding="ascii") as status:
        for line in status:
            if line.startswith(f"{field}:"):
                return int(line.split()[1]) * 1024
    return 0


def rss_mb(pid: int) -> float:
    return rss_bytes(pid) / MB


def peak_rss_mb(pid: int) -> float:
    """The peak resident set size of ``pid`` since it started (the kernel's VmHWM), MB."""
    return rss_bytes(pid, "VmHWM") / MB


def threads_of(process: subprocess.Popen[str]) -> int:
    """The number of threads of a running process."""
    status = Path(f"/proc/{process.pid}/status").read_text(encoding="ascii")
    return int(next(line for line in status.splitlines() if line.startswith("Threads:")).split()[1])


@dataclass(frozen=True)
class TcpSocket:
    """One IPv4 TCP socket of a process: its ports, and its state."""

    local_port: int
    remote_port: int
    listening: bool
    established: bool


#: ``/proc/net/tcp``'s states (include/net/tcp_states.h).
_ESTABLISHED, _LISTEN = "01", "0A"


def tcp_sockets(pid: int) -> list[TcpSocket]:
    """The IPv4 TCP sockets process ``pid`` holds (its descriptors' sockets, found in its
    network namespace's ``/proc/net/tcp``)."""
    inodes = set()
    for fd in Path(f"/proc/{pid}/fd").iterdir():
        try:
            target = os.readlink(fd)
        except OSError:  # closed meanwhile
            continue
        if target.startswith("socket:["):
            inodes.add(target.removeprefix("socket:[").removesuffix("]"))
    found = []
    for line in Path(f"/proc/{pid}/net/tcp").read_text(encoding="ascii").splitlines()[1:]:
        fields = line.split()
        if fields[9] in inodes:
            local, remote = (int(address.rpartition(":")[2], 16) for address in fields[1:3])
            found.append(TcpSocket(local, remote, fields[3] == _LISTEN, fields[3] == _ESTABLISHED))
    return found


@dataclass(frozen=True)
class Usage:
    """A process's resident memory and CPU time at one moment."""

    at: float
    rss_bytes: int
    cpu_seconds: float


def usage(pid: int) -> Usage:
    """Resident set size and user + system CPU time of process ``pid``, now."""
    return Usage(time.monotonic(), rss_bytes(pid), cpu_seconds(pid))


def cpu_percent(pid: int, seconds: float) -> float:
    """Percent of one core that ``pid`` used over the next ``seconds``."""
    before = usage(pid)
    time.sleep(seconds)
    after = usage(pid)
    return 100 * (after.cpu_seconds - before.cpu_seconds) / (after.at - before.at)


class PeakRss:
    """Samples a process's resident memory every 10 ms on a thread, keeping the peak (bytes)."""

    def __init__(self, pid: int) -> None:
        self._pid = pid
        self.peak = rss_bytes(pid)
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, daemon=True)
        self._thread.start()

    def _run(self) -> None:
        while not self._stop.wait(0.01):
            self.peak = max(self.peak, rss_bytes(self._pid))

    def stop(self) -> int:
        self._stop.set()
        self._thread.join()
        return self.peak

"""What would one SUB socket for a fleet's topics save against one per topic (issue 36)?

Usage: ``.venv/bin/python -m benchmarks.socket_sharing [--robots 10 25] [--seconds 15]
[--syscall-seconds 8] [--rounds 2]``.

The bridge gives every Gazebo topic a SUB socket of its own, so that each topic has its own TCP
connections and a flooded topic's back-pressure never holds another's messages
(``transport/zmq/socket_owner.py``). gz-transport's subscribers, and the C++ bridge, read every
topic of a process through one SUB socket. ``benchmarks.fleet_cpu_map`` found libzmq's receive
path (its I/O thread, ``zmq_msg_recv``) to be most of what a fleet message costs the bridge
beyond the rclpy ceiling. This measures that path alone, for both arrangements, with the C++
fleet simulator of ``benchmarks.fleet`` publishing (its ``/clock`` and every robot's odom, imu
and joint_states):

- ``per topic``: one SUB socket per topic, each subscribed to its topic and connected to the
  simulator, as the bridge does;
- ``shared``: one SUB socket subscribed to every topic, connected once, as gz-transport does.

Each runs in a ZeroMQ context of its own, read by one thread the way the native loop reads
(``native/loop.c``, ``pump_loop.c``): one epoll over every socket's ``ZMQ_FD``, each socket
read until EAGAIN. Per message: the reading thread's and libzmq's I/O thread's CPU
(``/proc/<pid>/task/<tid>/schedstat``) and wake-ups (voluntary context switches), then, in a
second window, their system calls (``perf stat``, where perf can count them). The reading
thread is Python here, so its CPU is an upper bound of what the native loop's would be; its
``getpid``, ``poll`` and ``read`` calls are libzmq's (its fork check, its mailbox), the same as
the native loop makes, while its ``futex`` calls and most of its wake-ups are Python's lock,
shared with the node's I/O thread.
The arrangements alternate, ``--rounds`` times each. Our own Gazebo node subscribes to every
topic (gz-transport publishes only to subscribers discovery told it about) and receives them
on its own context, which is not measured.
"""

from __future__ import annotations

import argparse
import os
import select
import statistics
import threading
import time
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from typing import Any

import zmq

from benchmarks import perf_syscalls
from benchmarks.bridge_threads import Reading, read_threads
from benchmarks.harness import ROOT, stop_all
from benchmarks.report import write_section
from benchmarks.results import store
from ros_gz_bridge_py.transport.zmq.node import ZmqGzNode
from testing import fleet_sim
from testing.gzpeer import start_peer, wait_for_line
from testing.run_env import run_env

MODES = ("per topic", "shared")
#: Where perf's files go.
WORK = ROOT / ".build" / "socket_sharing"


class Reader:
    """One arrangement's sockets in a context of their own, read by one thread."""

    def __init__(self, address: str, fqns: list[str], shared: bool) -> None:
        self.context = zmq.Context(1)
        groups = [fqns] if shared else [[fqn] for fqn in fqns]
        self.sockets = [self._socket(address, group) for group in groups]
        self.messages = 0
        self.tid = 0
        self._stopping = False
        self._thread = threading.Thread(target=self._run, name="bench-reader", daemon=True)

    def _socket(self, address: str, topics: list[str]) -> Any:
        sock = self.context.socket(zmq.SUB)
        for fqn in topics:
            sock.setsockopt(zmq.SUBSCRIBE, fqn.encode())
        sock.connect(address)
        return sock

    def start(self) -> None:
        self._thread.start()

    def _run(self) -> None:
        self.tid = threading.get_native_id()
        by_fd = {sock.getsockopt(zmq.FD): sock for sock in self.sockets}
        poller = select.epoll()
        for fd in by_fd:
            poller.register(fd, select.EPOLLIN)
        ready = list(self.sockets)
        while not self._stopping:
            for sock in ready:
                self._drain(sock)
            ready = [by_fd[fd] for fd, _ in poller.poll(0.1)]
        poller.close()

    def _drain(self, sock: Any) -> None:
        while True:
            try:
                sock.recv_multipart(zmq.NOBLOCK, copy=False)
            except zmq.Again:
                return
            self.messages += 1

    def close(self) -> None:
        self._stopping = True
        self._thread.join(5)
        for sock in self.sockets:
            sock.close(0)
        self.context.term()


@dataclass(frozen=True)
class Figures:
    """One window of one arrangement, per message the reader took."""

    mode: str
    rate: float
    reader_us: float
    reader_wakeups: float
    io_us: float
    io_wakeups: float
    #: System calls per message, by thread ("reader", "I/O") and call; empty without perf.
    syscalls: dict[str, dict[str, float]]


def _use(
    before: dict[int, Reading], after: dict[int, Reading], tids: set[int]
) -> tuple[float, int]:
    """CPU seconds and voluntary switches of ``tids`` between two readings."""
    cpu = sum(after[t].run_ns - before[t].run_ns for t in tids if t in before and t in after)
    woke = sum(after[t].voluntary - before[t].voluntary for t in tids if t in before and t in after)
    return cpu / 1e9, woke


def measure(reader: Reader, io_tids: set[int], mode: str, args: argparse.Namespace) -> Figures:
    """The clean window, then the system calls' (see the module docstring)."""
    seconds, syscall_seconds = args.seconds, args.syscall_seconds
    pid = os.getpid()
    before, taken, began = read_threads(pid), reader.messages, time.monotonic()
    time.sleep(seconds)
    after, taken, elapsed = read_threads(pid), reader.messages - taken, time.monotonic() - began
    reader_cpu, reader_woke = _use(before, after, {reader.tid})
    io_cpu, io_woke = _use(before, after, io_tids)
    per = max(taken, 1)
    calls: dict[str, dict[str, float]] = {}
    if syscall_seconds > 0 and perf_syscalls.missing() is None:
        start = reader.messages
        counted = perf_syscalls.count(pid, syscall_seconds, WORK / "perf.txt")
        counted_taken = max(reader.messages - start, 1)
        for role, tids in (("reader", {reader.tid}), ("I/O", io_tids)):
            totals: dict[str, int] = {}
            for (_, tid), named in counted.items():
                if tid in tids:
                    for name, n in named.items():
                        totals[name] = totals.get(name, 0) + n
            calls[role] = {name: n / counted_taken for name, n in totals.items()}
    return Figures(
        mode,
        taken / elapsed,
        reader_cpu / per * 1e6,
        reader_woke / per,
        io_cpu / per * 1e6,
        io_woke / per,
        calls,
    )


@contextmanager
def fleet(robots: int) -> Iterator[tuple[str, list[str]]]:
    """The simulator publishing to a subscriber of each topic: its address and the topics'
    wire names."""
    names = fleet_sim.robots(robots)
    spec = fleet_sim.write_spec(WORK / f"fleet_{robots}.spec", names)
    simulator = start_peer("pub-fleet", str(spec), "0", env=run_env())
    try:
        wait_for_line(simulator, r"^READY$", 60)
        topics = [fleet_sim.CLOCK_TOPIC, *(k.topic(r) for r in names for k in fleet_sim.KINDS)]
        with ZmqGzNode() as node:
            for topic in topics:
                node.subscribe(topic, lambda _payload, _info: None)
            deadline = time.monotonic() + 30
            while not all(node.topic_info(t) for t in topics):
                if time.monotonic() > deadline:
                    missing = "the simulator's topics were not all discovered in 30 s"
                    raise RuntimeError(missing)
                time.sleep(0.2)
            addresses = {info.address for t in topics for info in node.topic_info(t)}
            if len(addresses) != 1:
                unexpected = f"expected one publisher address, found {sorted(addresses)}"
                raise RuntimeError(unexpected)
            yield addresses.pop(), [node.fqn(t) for t in topics]
    finally:
        simulator.terminate()
        simulator.wait(10)


def one_round(address: str, fqns: list[str], mode: str, args: argparse.Namespace) -> Figures:
    """One arrangement: its reader started, settled, measured, closed."""
    before = set(read_threads(os.getpid()))
    reader = Reader(address, fqns, shared=mode == "shared")
    reader.start()
    time.sleep(3.0)  # connected, subscriptions through to the publisher, steady
    now = read_threads(os.getpid())
    io_tids = {tid for tid in set(now) - before if now[tid].comm.startswith("ZMQbg/IO")}
    try:
        return measure(reader, io_tids, mode, args)
    finally:
        reader.close()


def _offered(robots: int) -> float:
    return fleet_sim.CLOCK_HZ + robots * sum(kind.hz for kind in fleet_sim.KINDS)


def _calls(named: dict[str, float]) -> str:
    top = sorted(named.items(), key=lambda item: -item[1])[:4]
    return f"{sum(named.values()):.2f} (" + ", ".join(f"{n} {v:.2f}" for n, v in top) + ")"


def section(results: dict[int, list[Figures]], args: argparse.Namespace, load: float) -> str:
    """The report: each round, then the mean of each arrangement per fleet size."""
    lines = [
        "## One SUB socket per topic, or one for every topic (issue 36)\n",
        f"Command: `.venv/bin/python -m benchmarks.socket_sharing --robots "
        f"{' '.join(map(str, args.robots))} --seconds {args.seconds:g} --syscall-seconds "
        f"{args.syscall_seconds:g} --rounds {args.rounds}`. 1-minute load average {load:.2f} "
        "at the start. What is measured, and why: `benchmarks/socket_sharing.py`'s docstring. "
        "Per message the reader took. The reader is Python, so its CPU is an upper bound of "
        "the native loop's; its `getpid`, `poll` and `read` calls are libzmq's, as the native "
        "loop makes them, its `futex` calls and most of its wake-ups Python's lock.\n",
    ]
    for robots, rounds in results.items():
        lines += [
            f"\n### {robots} robots ({1 + len(fleet_sim.KINDS) * robots} topics from one simulator "
            f"process, {_offered(robots):,.0f} messages a second offered)\n",
            "| round | sockets | messages/s | reader, µs | reader wake-ups | libzmq I/O, µs "
            "| I/O wake-ups | reader system calls | I/O system calls |",
            "|---|---|---|---|---|---|---|---|---|",
        ]
        for i, f in enumerate(rounds):
            calls = [_calls(f.syscalls[r]) if r in f.syscalls else "-" for r in ("reader", "I/O")]
            lines.append(
                f"| {i // len(MODES) + 1} | {f.mode} | {f.rate:,.0f} | {f.reader_us:.2f} | "
                f"{f.reader_wakeups:.2f} | {f.io_us:.2f} | {f.io_wakeups:.2f} | {calls[0]} | "
                f"{calls[1]} |"
            )
        means = {m: [f for f in rounds if f.mode == m] for m in MODES}
        io = {m: statistics.mean(f.io_us for f in fs) for m, fs in means.items()}
        reader = {m: statistics.mean(f.reader_us for f in fs) for m, fs in means.items()}
        lines.append(
            f"\nMean over the rounds: libzmq's I/O thread {io['per topic']:.2f} µs per message "
            f"with a socket per topic, {io['shared']:.2f} with one shared "
            f"({io['per topic'] - io['shared']:+.2f} saved); the reader {reader['per topic']:.2f} "
            f"and {reader['shared']:.2f} ({reader['per topic'] - reader['shared']:+.2f}).\n"
        )
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(prog="benchmarks.socket_sharing")
    parser.add_argument("--robots", type=int, nargs="+", default=[10, 25])
    parser.add_argument("--seconds", type=float, default=15.0)
    parser.add_argument("--syscall-seconds", type=float, default=8.0)
    parser.add_argument("--rounds", type=int, default=2)
    args = parser.parse_args(argv)
    os.environ.update(run_env())  # our Gazebo node meets the simulator
    load = os.getloadavg()[0]
    results: dict[int, list[Figures]] = {}
    try:
        for robots in args.robots:
            with fleet(robots) as (address, fqns):
                results[robots] = [
                    one_round(address, fqns, mode, args)
                    for i in range(args.rounds)
                    for mode in (MODES if i % 2 == 0 else MODES[::-1])
                ]
    finally:
        stop_all()
    numbers = {
        f"{robots}_{f.mode.replace(' ', '_')}_{what}_us": statistics.mean(
            getattr(g, what + "_us") for g in rounds if g.mode == f.mode
        )
        for robots, rounds in results.items()
        for f in rounds
        for what in ("io", "reader")
    }
    store("socket_sharing", {}, load, numbers)
    write_section("socket_sharing", section(results, args, load))


if __name__ == "__main__":
    main()

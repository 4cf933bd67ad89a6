"""Gazebo Transport throughput and latency: our Python node against the real C++ ign-transport 11.

Usage, from the repository root: ``.venv/bin/python -m benchmarks.transport [--seconds S]``;
it writes the report ``benchmarks/reports/transport.md``. Every case is one publisher process and
one subscriber process exchanging ``ignition.msgs.Bytes`` whose data starts with the
CLOCK_MONOTONIC send time (ns, int64 little-endian). C++ ends are the test peer
(``testing/peer``, modes bench-pub/bench-sub); Python ends are this module run as
``... pub|sub ...``. Each case has two phases: back-to-back publishing (subscriber rate) and
paced publishing (latency without queueing). Traffic stays on loopback (loopback-env settings).
"""

from __future__ import annotations

import argparse
import os
import re
import signal
import statistics
import struct
import sys
import threading
import time
import uuid
from dataclasses import dataclass
from typing import Any

from benchmarks.report import write_section
from ros_gz_bridge_py.msgs import message_class
from ros_gz_bridge_py.transport import create_gz_node
from testing.gzpeer import peer_binary, start_process, stop_processes, wait_for_line

BYTES_TYPE = "ignition.msgs.Bytes"
STAMP = struct.Struct("<q")
SIZES = (200, 1_000_000, 6_000_000)
#: Paced rate of the latency phase per payload size (well under every pair's capacity).
LATENCY_HZ = {200: 500.0, 1_000_000: 50.0, 6_000_000: 15.0}
#: ZeroMQ high-water mark (messages) for payloads >= 1 MB, so a back-to-back publisher
#: queues at most ~HWM x 6 MB instead of gz's default 1000 x 6 MB.
LARGE_HWM = 20
PAIRS = (("cpp", "cpp"), ("cpp", "py"), ("py", "cpp"), ("py", "py"))
NAMES = {"cpp": "C++", "py": "Python"}
HEADER = (
    "| payload | publisher -> subscriber | rate msg/s | MB/s | received/sent "
    "| median µs | p99 µs | received/sent (paced) |\n|---|---|---|---|---|---|---|---|"
)
STATS_LINE = re.compile(
    r"STATS count=(\d+) bytes=(\d+) seconds=([\d.]+) rate=([\d.]+) "
    r"median_us=([\d.]+) p99_us=([\d.]+)"
)


def loopback_env() -> None:
    """The settings of shared/tools/loopback-env, with a partition of this run's own."""
    partition = os.environ.get("GZ_PARTITION") or f"bench-{os.getpid()}-{uuid.uuid4().hex[:6]}"
    os.environ.update(
        {"GZ_IP": "127.0.0.1", "IGN_IP": "127.0.0.1", "GZ_PARTITION": partition,
         "IGN_PARTITION": partition}
    )  # fmt: skip
    for name in ("GZ_RELAY", "IGN_RELAY", "GZ_TRANSPORT_IMPLEMENTATION"):
        os.environ.pop(name, None)


def data_offset(payload: bytes) -> int:
    """Where ``data`` starts in a serialized Bytes message (field-2 tag, varint length, data)."""
    position = 1
    while payload[position] & 0x80:
        position += 1
    return position + 1


# --- worker roles (run in their own process) ------------------------------------------------


def run_pub(topic: str, size: int, seconds: float, hz: float) -> None:
    """Publish stamped Bytes for ``seconds`` after a subscriber connects (like bench-pub)."""
    stop = _stop_on_sigterm()
    message = bytearray(message_class(BYTES_TYPE)(data=bytes(max(size, 8))).SerializeToString())
    at = data_offset(bytes(message))
    with create_gz_node() as node:
        publisher = node.advertise(topic, BYTES_TYPE)
        print("READY", flush=True)
        deadline = time.monotonic() + 5
        while not publisher.has_connections() and time.monotonic() < deadline:
            time.sleep(0.01)
        if not publisher.has_connections():
            print("NO_CONNECTIONS", flush=True)
            return
        print("CONNECTED", flush=True)
        time.sleep(0.3)
        start = time.monotonic_ns()
        end = start + int(seconds * 1e9)
        period = int(1e9 / hz) if hz > 0 else 0
        sent = 0
        next_send = start
        while not stop.is_set() and (now := time.monotonic_ns()) < end:
            if period:
                if now < next_send:
                    time.sleep((next_send - now) / 1e9)
                next_send += period
            STAMP.pack_into(message, at, time.monotonic_ns())
            publisher.publish_raw(bytes(message))
            sent += 1
        print(f"SENT {sent} SECONDS {(time.monotonic_ns() - start) / 1e9:.3f}", flush=True)
        time.sleep(0.5)


def run_sub(topic: str, seconds: float) -> None:
    """Receive stamped Bytes until SIGTERM or ``seconds``; print a STATS line (like bench-sub)."""
    stop = _stop_on_sigterm()
    latencies_ns: list[int] = []
    arrivals: list[int] = []
    total = [0]

    def on_message(payload: bytes, _info: Any) -> None:
        now = time.monotonic_ns()
        (stamp,) = STAMP.unpack_from(payload, data_offset(payload))
        latencies_ns.append(now - stamp)
        arrivals.append(now)
        total[0] += len(payload)

    with create_gz_node() as node:
        subscription = node.subscribe(topic, on_message, BYTES_TYPE)
        print("READY", flush=True)
        stop.wait(seconds)
        subscription.close()
    print(stats_line(latencies_ns, arrivals, total[0]), flush=True)


def stats_line(latencies_ns: list[int], arrivals: list[int], total: int) -> str:
    """The same STATS line the C++ bench-sub prints."""
    count = len(latencies_ns)
    span = (arrivals[-1] - arrivals[0]) / 1e9 if count > 1 else 0.0
    rate = (count - 1) / span if span > 0 else 0.0
    ordered = sorted(latencies_ns)
    median = statistics.median(ordered) / 1e3 if ordered else 0.0
    p99 = ordered[min(len(ordered) - 1, round(0.99 * (len(ordered) - 1)))] / 1e3 if ordered else 0
    return (
        f"STATS count={count} bytes={total} seconds={span:.3f} rate={rate:.1f} "
        f"median_us={median:.1f} p99_us={p99:.1f}"
    )


def _stop_on_sigterm() -> threading.Event:
    stop = threading.Event()
    signal.signal(signal.SIGTERM, lambda *_: stop.set())
    return stop


# --- the driver -----------------------------------------------------------------------------


@dataclass(frozen=True)
class Phase:
    """What the subscriber of one phase measured."""

    sent: int
    received: int
    rate: float
    median_us: float
    p99_us: float


@dataclass(frozen=True)
class Case:
    publisher: str
    subscriber: str
    size: int
    throughput: Phase
    latency: Phase


def _command(kind: str, role: str, *args: str) -> list[str]:
    if kind == "cpp":
        return [str(peer_binary()), f"bench-{role}", *args]
    return [sys.executable, "-m", "benchmarks.transport", role, *args]


def run_phase(publisher: str, subscriber: str, size: int, seconds: float, hz: float) -> Phase:
    """One publisher/subscriber pair for ``seconds`` of publishing at ``hz`` (0: flat out)."""
    topic = f"/bench_{os.getpid()}_{uuid.uuid4().hex[:8]}"
    env = dict(os.environ)
    if size >= 1_000_000:
        for prefix in ("GZ_", "IGN_"):
            env[f"{prefix}TRANSPORT_SNDHWM"] = env[f"{prefix}TRANSPORT_RCVHWM"] = str(LARGE_HWM)
    try:
        sub = start_process(_command(subscriber, "sub", topic, str(seconds + 30)), env)
        wait_for_line(sub, r"^READY$", 30)
        pub = start_process(
            _command(publisher, "pub", topic, str(size), str(seconds), "--hz", str(hz)), env
        )
        wait_for_line(pub, r"^CONNECTED$", 30)
        sent = int(wait_for_line(pub, r"^SENT (\d+)", seconds + 30)[1])
        time.sleep(0.5)  # let the last messages drain
        sub.stop(grace=10)
        stats = wait_for_line(sub, STATS_LINE.pattern, 5)
    finally:
        stop_processes()
    return Phase(sent, int(stats[1]), float(stats[4]), float(stats[5]), float(stats[6]))


def run_all(seconds: float, sizes: tuple[int, ...]) -> list[Case]:
    cases = []
    for size in sizes:
        for publisher, subscriber in PAIRS:
            throughput = run_phase(publisher, subscriber, size, seconds, 0.0)
            latency = run_phase(publisher, subscriber, size, seconds, LATENCY_HZ[size])
            case = Case(publisher, subscriber, size, throughput, latency)
            print(describe(case), file=sys.stderr, flush=True)
            cases.append(case)
    return cases


def _size(size: int) -> str:
    return f"{size // 1_000_000} MB" if size >= 1_000_000 else f"{size} B"


def describe(case: Case) -> str:
    t, lat = case.throughput, case.latency
    return (
        f"| {_size(case.size)} | {NAMES[case.publisher]} -> {NAMES[case.subscriber]} "
        f"| {t.rate:,.0f} | {t.rate * case.size / 1e6:,.0f} | {t.received}/{t.sent} "
        f"| {lat.median_us:,.0f} | {lat.p99_us:,.0f} | {lat.received}/{lat.sent} |"
    )


def goal_lines(cases: list[Case]) -> list[str]:
    """The two goals, each with the numbers it was judged on."""
    by_key = {(c.publisher, c.subscriber, c.size): c for c in cases}
    lines = []
    for size in (s for s in SIZES if s >= 1_000_000):
        base, ours = by_key.get(("cpp", "cpp", size)), by_key.get(("cpp", "py", size))
        if base and ours and base.throughput.rate > 0:
            share = ours.throughput.rate / base.throughput.rate
            verdict = "met" if share >= 0.8 else "NOT met"
            lines.append(
                f"- Python subscriber >= 80% of the C++->C++ rate at {_size(size)}: "
                f"{share:.0%} ({ours.throughput.rate:,.0f} vs {base.throughput.rate:,.0f} msg/s)"
                f" — {verdict}"
            )
    base = by_key.get(("cpp", "cpp", 200))
    for pair in (("cpp", "py"), ("py", "cpp")):
        ours = by_key.get((*pair, 200))
        if base and ours:
            added = ours.latency.median_us - base.latency.median_us
            verdict = "met" if added < 100 else "NOT met"
            lines.append(
                f"- < 100 µs added median latency at 200 B, {NAMES[pair[0]]} -> "
                f"{NAMES[pair[1]]}: {added:+,.0f} µs ({ours.latency.median_us:,.0f} vs "
                f"{base.latency.median_us:,.0f} µs) — {verdict}"
            )
    return lines


def markdown(cases: list[Case], seconds: float, load: float) -> str:
    hz = ", ".join(f"{_size(size)} at {rate:g} Hz" for size, rate in LATENCY_HZ.items())
    rows = "\n".join(describe(case) for case in cases)
    return f"""## Gazebo Transport (ZeroMQ): Python node vs real ign-transport 11

Command: `.venv/bin/python -m benchmarks.transport --seconds {seconds:g}`

One publisher process and one subscriber process per row, `ignition.msgs.Bytes` stamped with
CLOCK_MONOTONIC. Rate: subscriber messages/s while the publisher sends back to back for
{seconds:g} s (ZeroMQ HWM {LARGE_HWM} messages for payloads >= 1 MB, else the default 1000;
excess is dropped at the publisher). Latency: publisher paced ({hz}), send to callback.
1-minute load average before the run: {load:.2f} (other work on the machine skews the numbers).

{HEADER}
{rows}

Goals:
{chr(10).join(goal_lines(cases))}
"""


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    roles = parser.add_subparsers(dest="role")
    pub = roles.add_parser("pub", help="worker: publish stamped Bytes")
    pub.add_argument("topic")
    pub.add_argument("size", type=int)
    pub.add_argument("seconds", type=float)
    pub.add_argument("--hz", type=float, default=0.0)
    sub = roles.add_parser("sub", help="worker: receive stamped Bytes, print STATS")
    sub.add_argument("topic")
    sub.add_argument("seconds", type=float)
    parser.add_argument("--seconds", type=float, default=2.0, help="publishing time per phase")
    parser.add_argument("--sizes", type=int, nargs="+", default=list(SIZES), choices=SIZES)
    args = parser.parse_args(argv)

    loopback_env()
    if args.role == "pub":
        run_pub(args.topic, args.size, args.seconds, args.hz)
    elif args.role == "sub":
        run_sub(args.topic, args.seconds)
    else:
        load = os.getloadavg()[0]
        cases = run_all(args.seconds, tuple(args.sizes))
        write_section("transport", markdown(cases, args.seconds, load))
    return 0


if __name__ == "__main__":
    sys.exit(main())

"""How much memory a fleet's bridge holds over time, and what bounds it (issue 36 item 5).

Usage: ``.venv/bin/python -m benchmarks.fleet_memory [--robots 50] [--seconds 60] [--rounds 2]
[--low-hwm 50] [--flood-rounds 3]``.

Three parts. First, what libzmq keeps for a small message waiting in a SUB socket's receive pipe:
a publisher process sends messages to a subscriber that does not read them (RCVHWM 0: no
limit), paced (a gap between messages, so each arrives in a read of its own, as a simulator's
topics at 50 Hz to 1 kHz do) and back to back; the subscriber's anonymous resident memory
(RssAnon) before and after, per message. Second, the fleet of ``benchmarks.fleet`` through a
bridge for a long window, the bridge's memory read every second (VmRSS, RssAnon) and its peak
since its start (VmHWM), its CPU and CPU per message its subscribers took (Gazebo -> ROS), and
the share of ``/clock`` its subscriber got; rounds alternate gz-transport's receive queue of
1000 messages a topic (``GZ_TRANSPORT_RCVHWM=1000`` in the bridge's environment) and the
bridge's default, planned from the number of Gazebo topics of its configuration
(``transport/settings.py`` ``planned_rcvhwm``). Third, what a lower mark costs where one topic
is flooded: Odometry offered at 20 kHz for a few seconds through one native channel to a
subscriber taking it serialized (``benchmarks.native_overload``'s flow), a busy loop (``yes``)
beside the bridge all along, a fresh bridge each round, the default (1000 for one topic) and
the low mark alternating.
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import time
from collections.abc import Sequence
from dataclasses import dataclass

import zmq

from benchmarks.bridged import Backend, bridge_process, flow_through
from benchmarks.busy_loops import busy_loops
from benchmarks.fleet_rounds import start_bridged
from benchmarks.harness import Flow, FlowResult, bridge_config, stop_all, topic_name
from benchmarks.native_overload import QUEUE
from benchmarks.native_paths import path_backend
from benchmarks.report import write_section
from ros_gz_bridge_py.transport.settings import DEFAULT_HWM, planned_rcvhwm
from testing import fleet_sim
from testing.loopback import free_port
from testing.procstat import MB, cpu_seconds, rss_bytes
from testing.run_env import run_env

#: Part one: how many messages, of what size, and the gap that makes each arrive alone.
QUEUED, SMALL, PACED_GAP = 5000, 600, 0.0002
#: Part three: the offered rate and seconds of each round.
FLOOD_HZ, FLOOD_SECONDS = 20000.0, 4.0


def _publish(port: int, count: int, size: int, gap: float) -> None:
    """The publisher process of part one: ``count`` messages to whoever subscribes at ``port``."""
    context = zmq.Context()
    pub = context.socket(zmq.PUB)
    pub.setsockopt(zmq.SNDHWM, 0)
    pub.bind(f"tcp://127.0.0.1:{port}")
    time.sleep(1.5)  # the subscriber connects and its subscription arrives
    for _ in range(count):
        pub.send_multipart([b"/topic", b"x" * size])
        if gap:
            time.sleep(gap)
    pub.close(linger=-1)  # every message handed to TCP before the process ends
    context.term()


def queued_cost(count: int, size: int, gap: float) -> float:
    """Bytes of this process's anonymous memory per message waiting, unread, in a SUB socket's
    receive pipe, ``count`` messages of ``size`` bytes sent ``gap`` seconds apart."""
    port = free_port()
    publisher = [sys.executable, "-m", "benchmarks.fleet_memory", "--publish", str(port)]
    sending = subprocess.Popen([*publisher, str(count), str(size), str(gap)])
    context = zmq.Context()
    sub = context.socket(zmq.SUB)
    sub.setsockopt(zmq.RCVHWM, 0)
    sub.setsockopt(zmq.SUBSCRIBE, b"")
    before = rss_bytes(os.getpid(), "RssAnon")
    sub.connect(f"tcp://127.0.0.1:{port}")
    if sending.wait(timeout=120):
        msg = f"the publisher of part one failed ({sending.returncode})"
        raise RuntimeError(msg)
    time.sleep(0.5)  # the last reads reach the pipe
    grown = rss_bytes(os.getpid(), "RssAnon") - before
    sub.close(linger=0)
    context.term()
    return grown / count


@dataclass(frozen=True)
class MemoryRound:
    #: GZ_TRANSPORT_RCVHWM in the bridge's environment ("" for unset).
    hwm: str
    seconds: float
    #: MB: the peak since the bridge started (VmHWM); VmRSS and RssAnon read every second.
    peak: float
    rss: list[float]
    anon: list[float]
    clock_share: float
    load: float
    #: Bridge CPU, % of one core, and µs per message its subscribers took (Gazebo -> ROS).
    cpu: float
    per_message_us: float
    #: The default receive HWM planned for this fleet's topics.
    planned: int

    def cells(self) -> str:
        rss, anon = self.rss, self.anon
        mark = self.hwm or f"{self.planned} (default, planned)"
        return (
            f"{mark} | {self.peak:.0f} | {statistics.median(rss):.0f} "
            f"| {max(rss):.0f} | {statistics.median(anon):.0f} | {max(anon):.0f} "
            f"| {self.cpu:.1f}% | {self.per_message_us:.1f} "
            f"| {100 * self.clock_share:.1f}% | {self.load:.1f}"
        )


def memory_round(robots: int, seconds: float, hwm: str) -> MemoryRound:
    """The fleet of ``robots`` through a bridge whose topics' receive queues hold ``hwm``
    messages ("": the bridge's default), its memory read every second for ``seconds``."""
    load = os.getloadavg()[0]
    env = run_env()
    if hwm:
        env = {**env, "GZ_TRANSPORT_RCVHWM": hwm}
    fleet = start_bridged(robots, env)
    try:
        pid = fleet.bridge.pid
        counted = fleet.subscribers.counts()
        cpu_before = cpu_seconds(pid)
        began = time.monotonic()
        rss, anon = [], []
        while time.monotonic() - began < seconds:
            time.sleep(1.0)
            rss.append(rss_bytes(pid) / MB)
            anon.append(rss_bytes(pid, "RssAnon") / MB)
        counts = fleet.subscribers.counts()
        cpu = cpu_seconds(pid) - cpu_before
        window = time.monotonic() - began
        peak = rss_bytes(pid, "VmHWM") / MB
        fleet.finish()
    finally:
        stop_all()
    clock = counts[fleet_sim.CLOCK_TOPIC] - counted[fleet_sim.CLOCK_TOPIC]
    taken = sum(n - counted.get(topic, 0) for topic, n in counts.items() if topic != "cmd_vel")
    planned = planned_rcvhwm(1 + 3 * robots)  # /clock, and odom, imu, joint_states a robot
    return MemoryRound(
        hwm, window, peak, rss, anon, clock / (fleet_sim.CLOCK_HZ * window), load,
        100 * cpu / window, 1e6 * cpu / max(taken, 1), planned,
    )  # fmt: skip


def flooded_topic(hwm: str) -> FlowResult:
    """Odometry at :data:`FLOOD_HZ` through a fresh bridge whose receive queue holds ``hwm``
    messages ("": the default) to a subscriber taking it serialized."""
    native = path_backend("native")
    env = {**native.bridge_env, **({"GZ_TRANSPORT_RCVHWM": hwm} if hwm else {})}
    topic = topic_name("fleet_memory_flood")
    arguments = bridge_config([(topic, "odometry", "gz2ros")], QUEUE)
    with bridge_process(arguments, env, channels=1) as bridge:
        flow = Flow("gz-pub", "ros-sub", "odometry", FLOOD_SECONDS, FLOOD_HZ, depth=QUEUE, raw=True)
        return flow_through(flow, topic, Backend(native.name, env, native.gz_env), bridge)


def flood_cells(hwm: str, r: FlowResult) -> str:
    if r.error:
        return f"{hwm or '1000 (default)'} | failed: {r.error} | | |"
    cpu = "-" if r.cpu is None else f"{r.cpu:.0f}%"
    return (
        f"{hwm or '1000 (default)'} | {r.received}/{r.sent} ({r.share:.1%}) | {cpu} "
        f"| {r.p99_us / 1000:.1f} ms"
    )


def report(
    costs: dict[str, float],
    robots: int,
    rounds: list[MemoryRound],
    floods: list[tuple[str, FlowResult]],
    command: str,
) -> str:
    lines = [
        "## How much memory a fleet's bridge holds (issue 36 item 5)",
        "",
        f"Command: `{command}`",
        "",
        (__doc__ or "").split("\n\n", 2)[2].strip(),
        "",
        f"### libzmq's receive pipe: {QUEUED} messages of {SMALL} bytes, unread",
        "",
        "| sent | per waiting message |",
        "| --- | --- |",
        *(f"| {how} | {cost:,.0f} bytes |" for how, cost in costs.items()),
        "",
        *_fleet_section(robots, rounds),
        f"### One topic flooded: Odometry at {FLOOD_HZ / 1000:g} kHz for {FLOOD_SECONDS:g} s, "
        "a busy loop beside the bridge",
        "",
        "| round | RCVHWM | delivered/sent | bridge CPU | p99 latency |",
        "| --- | --- | --- | --- | --- |",
        *(f"| {index} | {flood_cells(*f)} |" for index, f in enumerate(floods, 1)),
    ]
    return "\n".join(lines)


def _fleet_section(robots: int, rounds: list[MemoryRound]) -> list[str]:
    """The fleet part's lines; none but a word when it ran no round (``--rounds 0``)."""
    if not rounds:
        return [f"### The fleet of {robots} robots: no round (`--rounds 0`)", ""]
    return [
        f"### The fleet of {robots} robots, each window about {rounds[0].seconds:.0f} s",
        "",
        "| round | RCVHWM | peak MB (VmHWM) | RSS median MB | RSS max MB | RssAnon median MB "
        "| RssAnon max MB | bridge CPU | µs per message taken | /clock delivered | 1-min load |",
        "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |",
        *(f"| {index} | {r.cells()} |" for index, r in enumerate(rounds, 1)),
        "",
    ]


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0] if __doc__ else None)
    parser.add_argument("--robots", type=int, default=50)
    parser.add_argument("--seconds", type=float, default=60.0)
    parser.add_argument("--rounds", type=int, default=2, help="pairs of rounds")
    parser.add_argument("--low-hwm", type=int, default=50)
    parser.add_argument("--flood-rounds", type=int, default=3, help="pairs of flooded rounds")
    parser.add_argument("--publish", type=float, nargs=4, help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.publish:
        port, count, size, gap = args.publish
        _publish(int(port), int(count), int(size), gap)
        return 0
    costs = {
        f"paced, {PACED_GAP * 1e6:.0f} µs apart": queued_cost(QUEUED, SMALL, PACED_GAP),
        "back to back": queued_cost(QUEUED, SMALL, 0.0),
    }
    print(costs, flush=True)
    rounds = []
    for index in range(args.rounds):
        gz_transport = str(DEFAULT_HWM)
        for hwm in (gz_transport, "") if index % 2 == 0 else ("", gz_transport):
            rounds.append(memory_round(args.robots, args.seconds, hwm))
            print(rounds[-1].cells(), flush=True)
    floods = []
    with busy_loops(1):
        for index in range(args.flood_rounds):
            for hwm in ("", str(args.low_hwm)) if index % 2 == 0 else (str(args.low_hwm), ""):
                floods.append((hwm, flooded_topic(hwm)))
                print(flood_cells(*floods[-1]), flush=True)
    command = (
        f".venv/bin/python -m benchmarks.fleet_memory --robots {args.robots} "
        f"--seconds {args.seconds:g} --rounds {args.rounds} --low-hwm {args.low_hwm} "
        f"--flood-rounds {args.flood_rounds}"
    )
    write_section("fleet_memory", report(costs, args.robots, rounds, floods, command))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

"""The rounds of the fleet benchmark: the fleet through a bridge, the same ROS traffic from one
rclpy process (the ceiling), and the fleet's bridge alone at rest (``benchmarks.fleet`` says
what each runs). :func:`start_bridged` and :func:`start_ceiling` are also the fleets of
``benchmarks.fleet_cpu_map``."""

from __future__ import annotations

import dataclasses
import os
import sys
import time
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

from benchmarks.fleet_goals import KINDS, Idle, Round, offered_rate, total_offered
from benchmarks.fleet_subscribers import Subscribers, counts_of
from benchmarks.harness import BIN, ROOT, CpuWindow, FlowFailure, stop_all
from testing import fleet_sim
from testing.e2e_harness import status_rows
from testing.gzpeer import PeerProcess, start_peer, start_process, wait_for_line
from testing.procstat import peak_rss_mb, rss_mb, threads_of
from testing.run_env import run_env

#: Seconds between every topic flowing and the measured window (late matches settle).
SETTLE = 2.0
#: Seconds between an idle bridge's start and its measured window: past its start-up (a
#: 201-entry bridge takes up to 7 s on a loaded machine) and its first explanation passes.
IDLE_SETTLE = 15.0


@dataclass(frozen=True)
class Window:
    """One measured window of a round: the subscribers' counts at either end, the CPU of the
    measured process and of the subscribers, and the measured process at the end."""

    seconds: float
    before: dict[str, int]
    after: dict[str, int]
    cpu: float
    sub_cpu: float
    threads: int
    rss: float
    rss_peak: float

    def arrived(self, topic_filter: str | None = None) -> int:
        """Messages the subscribers took in the window (Gazebo -> ROS topics), of one kind
        with ``topic_filter``."""
        return sum(
            self.after[t] - self.before[t]
            for t in self.after
            if t != "cmd_vel" and (topic_filter is None or _of_kind(t, topic_filter))
        )

    def commands(self) -> int:
        """``cmd_vel`` messages the subscribers sent in the window."""
        return self.after["cmd_vel"] - self.before["cmd_vel"]


def _of_kind(topic: str, kind: str) -> bool:
    return topic == f"/{kind}" or topic.endswith(f"/{kind}")


def measure(subscribers: Subscribers, measured: PeerProcess, seconds: float) -> Window:
    """``seconds`` of the subscribers' counts and of the CPU of ``measured`` and of them."""
    before = subscribers.counts()
    window = CpuWindow(measured.pid)
    sub_before = subscribers.cpu_seconds()
    window.begin()
    began = time.monotonic()
    time.sleep(seconds)
    window.end()
    wall = time.monotonic() - began
    sub_cpu = 100 * (subscribers.cpu_seconds() - sub_before) / wall
    return Window(
        seconds=wall,
        before=before,
        after=subscribers.counts(),
        cpu=window.percent or 0.0,
        sub_cpu=sub_cpu,
        threads=threads_of(measured),
        rss=rss_mb(measured.pid),
        rss_peak=peak_rss_mb(measured.pid),
    )


def delivered_shares(robots: int, window: Window) -> dict[str, float]:
    """Share of the schedule that arrived per Gazebo -> ROS kind."""
    return {
        kind: window.arrived(kind) / (offered_rate(robots, kind) * window.seconds)
        for kind in KINDS[:-1]
    }


@dataclass
class BridgedFleet:
    """A fleet running through a bridge: the simulator, the subscribers, the bridge."""

    robots: int
    simulator: PeerProcess
    subscribers: Subscribers
    bridge: PeerProcess
    #: When the simulator began publishing (monotonic) and the bridge started (wall clock).
    simulating: float
    started: float
    #: When every topic flowed (wall clock), None if some never did; those that did not.
    flowing: float | None
    silent: tuple[str, ...]
    silent_status: tuple[str, ...]

    @property
    def measured(self) -> PeerProcess:
        return self.bridge

    def finish(self) -> tuple[float, float]:
        """Stop the bridge, then the simulator: the share of the subscribers' commands the
        simulator received, and the share of its schedule the simulator kept."""
        self.bridge.stop(grace=10)
        commands_sent = self.subscribers.counts()["cmd_vel"]
        self.simulator.stop(grace=10)
        simulated = time.monotonic() - self.simulating
        sent = sum(_numbers(self.simulator, "SENT "))
        received = sum(_numbers(self.simulator, "RECEIVED "))
        schedule = (total_offered(self.robots) - offered_rate(self.robots, "cmd_vel")) * simulated
        return (received / commands_sent if commands_sent else 0.0), sent / schedule


def start_bridged(robots: int, env: Mapping[str, str]) -> BridgedFleet:
    """The simulator publishing, the subscribers, then the bridge, until every topic flows."""
    names = fleet_sim.robots(robots)
    spec = fleet_sim.write_spec(ROOT / ".build" / "bench_fleet" / f"fleet_{robots}.spec", names)
    simulator = start_peer("pub-fleet", str(spec), "0", env=env)
    wait_for_line(simulator, r"^READY$", 60)
    simulating = time.monotonic()
    subscribers = Subscribers.start(robots, env)
    time.sleep(1.0)  # the simulator publishes before the bridge starts, as a simulator does
    # This checkout's package, whichever the console script's environment installed.
    bridge_env = {**env, "PYTHONPATH": str(ROOT)}
    started = time.time()
    bridge = start_process(
        [str(BIN / "parameter_bridge"), *fleet_sim.bridge_arguments(names)], bridge_env
    )
    flowing, silent = subscribers.wait_flowing()
    silent_status = tuple(status_rows(bridge, silent)) if silent else ()
    time.sleep(SETTLE)
    return BridgedFleet(
        robots, simulator, subscribers, bridge, simulating, started, flowing, silent, silent_status
    )


def bridge_round(robots: int, seconds: float, env: Mapping[str, str], order: int = 0) -> Round:
    """The fleet of ``robots`` through ``parameter_bridge`` (see ``benchmarks.fleet``)."""
    load = os.getloadavg()[0]
    fleet = start_bridged(robots, env)
    window = measure(fleet.subscribers, fleet.bridge, seconds)
    commanded, simulator_share = fleet.finish()
    delivered = delivered_shares(robots, window)
    delivered["cmd_vel"] = commanded
    return Round(
        robots,
        ceiling=False,
        window_s=window.seconds,
        cpu=window.cpu,
        delivered=delivered,
        messages=window.arrived() + window.commands() * commanded,
        threads=window.threads,
        rss=window.rss,
        rss_peak=window.rss_peak,
        startup_s=None if fleet.flowing is None else fleet.flowing - fleet.started,
        silent=fleet.silent,
        silent_status=fleet.silent_status,
        sub_cpu=window.sub_cpu,
        simulator_share=simulator_share,
        load=load,
        order=order,
    )


def _numbers(proc: PeerProcess, prefix: str) -> list[int]:
    """The last word of every line of ``proc`` starting with ``prefix``, as an integer."""
    return [int(line.split()[-1]) for line in proc.output().splitlines() if line.startswith(prefix)]


@dataclass
class CeilingFleet:
    """The ceiling running: the subscribers, and the one rclpy process in the bridge's place."""

    robots: int
    subscribers: Subscribers
    publisher: PeerProcess
    #: When the publisher started, and when every topic flowed (wall clock; None: never).
    started: float
    flowing: float | None
    silent: tuple[str, ...]

    @property
    def measured(self) -> PeerProcess:
        return self.publisher

    def commands_taken(self) -> int:
        return counts_of(self.publisher)["cmd_vel"]

    def finish(self) -> tuple[float, float]:
        """The share of the subscribers' commands the publisher took, over the whole run (as
        the bridge's: what they sent, then what arrived), and 1 (no simulator)."""
        sent = self.subscribers.counts()["cmd_vel"]
        return (self.commands_taken() / sent if sent else 0.0), 1.0


def start_ceiling(robots: int, env: Mapping[str, str]) -> CeilingFleet:
    """The subscribers, then the ceiling's rclpy process, until every topic flows."""
    subscribers = Subscribers.start(robots, env)
    command = [sys.executable, "-m", "benchmarks.fleet_ros", "pub", str(robots)]
    started = time.time()
    publisher = start_process(command, env)
    flowing, silent = subscribers.wait_flowing()
    time.sleep(SETTLE)
    return CeilingFleet(robots, subscribers, publisher, started, flowing, silent)


def ceiling_round(robots: int, seconds: float, env: Mapping[str, str], order: int = 0) -> Round:
    """The same ROS topics from one rclpy process to the same subscriber processes, which
    command it as they command the bridge."""
    load = os.getloadavg()[0]
    fleet = start_ceiling(robots, env)
    taken_before = fleet.commands_taken()
    window = measure(fleet.subscribers, fleet.publisher, seconds)
    taken = fleet.commands_taken() - taken_before
    delivered = delivered_shares(robots, window)
    delivered["cmd_vel"] = fleet.finish()[0]
    return Round(
        robots,
        ceiling=True,
        window_s=window.seconds,
        cpu=window.cpu,
        delivered=delivered,
        messages=window.arrived() + taken,
        threads=window.threads,
        rss=window.rss,
        rss_peak=window.rss_peak,
        startup_s=None if fleet.flowing is None else fleet.flowing - fleet.started,
        silent=fleet.silent,
        sub_cpu=window.sub_cpu,
        load=load,
        order=order,
    )


def _at_rest(
    command: list[str], env: Mapping[str, str], seconds: float
) -> tuple[float, PeerProcess]:
    """CPU (% of a core) of ``command``'s process over ``seconds`` after IDLE_SETTLE, and the
    process (still running)."""
    process = start_process(command, env)
    time.sleep(IDLE_SETTLE)
    window = CpuWindow(process.pid)
    window.begin()
    time.sleep(seconds)
    window.end()
    return window.percent or 0.0, process


def idle_round(robots: int, seconds: float) -> Idle:
    """The fleet's bridge alone, no simulator, no subscriber: CPU over ``seconds``; then its
    ceiling at rest, the ceiling's rclpy process with the same endpoints sending nothing."""
    print(f"== idle bridge of {robots} robots", file=sys.stderr)
    env = {**run_env(), "PYTHONPATH": str(ROOT)}
    names = fleet_sim.robots(robots)
    bridge_command = [str(BIN / "parameter_bridge"), *fleet_sim.bridge_arguments(names)]
    ceiling_command = [
        sys.executable, "-m", "benchmarks.fleet_ros", "pub", str(robots), "--at-rest",
    ]  # fmt: skip
    try:
        cpu, bridge = _at_rest(bridge_command, env, seconds)
        result = Idle(robots, cpu, threads_of(bridge), rss_mb(bridge.pid))
    finally:
        stop_all()
    try:
        ceiling_cpu, _ceiling = _at_rest(ceiling_command, env, seconds)
        result = dataclasses.replace(result, ceiling_cpu=ceiling_cpu)
    finally:
        stop_all()
    print(result, file=sys.stderr, flush=True)
    return result


def run(robots: int, seconds: float, ceiling: bool, order: int = 0) -> Round:
    """One round; a round that fails is reported with its error and the others go on."""
    print(f"== {order}: fleet of {robots}, {'ceiling' if ceiling else 'bridge'}", file=sys.stderr)
    try:
        measure_round = ceiling_round if ceiling else bridge_round
        result = measure_round(robots, seconds, run_env(), order)
    except FlowFailure as error:  # reported in the table instead
        first = (str(error).strip().splitlines() or [type(error).__name__])[0]
        result = Round(robots, ceiling, error=first[:160], order=order)
    finally:
        stop_all()
    print(result, file=sys.stderr, flush=True)
    return result


def schedule(robots: Sequence[int], rounds: int) -> list[tuple[int, bool]]:
    """The run's rounds in order: per fleet size, ``rounds`` pairs of a bridge round and a
    ceiling round, the pair's order swapped every other time (bridge first, then ceiling
    first), so that a drift in the machine's load hits both sides alike."""
    order = []
    for count in robots:
        for repeat in range(rounds):
            pair = [(count, False), (count, True)]
            order += pair if repeat % 2 == 0 else pair[::-1]
    return order

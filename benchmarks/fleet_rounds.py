"""The rounds of the fleet benchmark: the fleet through a bridge, the same ROS traffic from one
rclpy process (the ceiling), and the fleet's bridge alone at rest (``benchmarks.fleet`` says
what each runs)."""

from __future__ import annotations

import json
import signal
import sys
import time
from collections.abc import Mapping
from dataclasses import dataclass

from benchmarks.fleet_goals import FLOW_TIMEOUT, KINDS, Idle, Round, offered_rate, total_offered
from benchmarks.harness import BIN, ROOT, CpuWindow, FlowFailure, stop_all
from testing import fleet_sim
from testing.e2e_harness import status_rows
from testing.gzpeer import PeerProcess, start_peer, start_process, wait_for_line
from testing.procstat import rss_mb, threads_of
from testing.run_env import run_env

#: Seconds between every topic flowing and the measured window (late matches settle).
SETTLE = 2.0
#: Seconds between an idle bridge's start and its measured window (its channels exist).
IDLE_SETTLE = 5.0


def _window(sub: PeerProcess, measured: PeerProcess, seconds: float) -> Window:
    """``seconds`` of the subscriber's counts and of the CPU of ``measured`` and ``sub``."""
    before = _counts(sub)
    windows = [CpuWindow(measured.pid), CpuWindow(sub.pid)]
    for window in windows:
        window.begin()
    began = time.monotonic()
    time.sleep(seconds)
    for window in windows:
        window.end()
    return Window(
        seconds=time.monotonic() - began,
        before=before,
        after=_counts(sub),
        cpu=windows[0].percent or 0.0,
        sub_cpu=windows[1].percent or 0.0,
        threads=threads_of(measured),
        rss=rss_mb(measured.pid),
    )


def _counts(sub: PeerProcess) -> dict[str, int]:
    """The subscriber's counts so far (it prints them on SIGUSR1)."""
    sub.send_signal(signal.SIGUSR1)
    counts: dict[str, int] = json.loads(wait_for_line(sub, r"^COUNTS (.*)$", 10)[1])
    return counts


def _wait_flowing(sub: PeerProcess) -> tuple[float | None, tuple[str, ...]]:
    """When (wall clock) every topic had brought the subscriber a message; if that does not
    happen within :data:`FLOW_TIMEOUT`, None and the topics that brought nothing (the run
    goes on: the delivered shares then show them)."""
    try:
        return float(wait_for_line(sub, r"^ALL_FLOWING (\S+)$", FLOW_TIMEOUT)[1]), ()
    except FlowFailure:
        counts = _counts(sub)
        return None, tuple(t for t, n in counts.items() if not n and t != "cmd_vel")


def _delivered(
    robots: int, before: Mapping[str, int], after: Mapping[str, int], seconds: float
) -> dict[str, float]:
    """Share of the schedule that arrived per Gazebo -> ROS kind."""
    shares = {}
    for kind in KINDS[:-1]:
        topics = [t for t in after if t != "cmd_vel" and (t == kind or t.endswith(f"/{kind}"))]
        arrived = sum(after[t] - before[t] for t in topics)
        shares[kind] = arrived / (offered_rate(robots, kind) * seconds)
    return shares


def _start_subscriber(robots: int, env: Mapping[str, str]) -> PeerProcess:
    sub = start_process([sys.executable, "-m", "benchmarks.fleet_ros", "sub", str(robots)], env)
    wait_for_line(sub, r"^READY$", 60)
    return sub


def bridge_round(robots: int, seconds: float, env: Mapping[str, str]) -> Round:
    """The fleet of ``robots`` through ``parameter_bridge`` (see the module docstring)."""
    names = fleet_sim.robots(robots)
    spec = fleet_sim.write_spec(ROOT / ".build" / "bench_fleet" / f"fleet_{robots}.spec", names)
    simulator = start_peer("pub-fleet", str(spec), "0", env=env)
    wait_for_line(simulator, r"^READY$", 60)
    simulating = time.monotonic()
    sub = _start_subscriber(robots, env)
    time.sleep(1.0)  # the simulator publishes before the bridge starts, as a simulator does
    # This checkout's package, whichever the console script's environment installed.
    bridge_env = {**env, "PYTHONPATH": str(ROOT)}
    started = time.time()
    bridge = start_process(
        [str(BIN / "parameter_bridge"), *fleet_sim.bridge_arguments(names)], bridge_env
    )
    flowing, silent = _wait_flowing(sub)
    silent_status = tuple(status_rows(bridge, silent)) if silent else ()
    time.sleep(SETTLE)
    measured = _window(sub, bridge, seconds)
    before, after = measured.before, measured.after
    bridge.stop(grace=10)
    commands_sent = _counts(sub)["cmd_vel"]
    simulator.stop(grace=10)
    simulated = time.monotonic() - simulating
    sent = [int(m) for m in _numbers(simulator, "SENT ")]
    received = sum(_numbers(simulator, "RECEIVED "))
    delivered = _delivered(robots, before, after, measured.seconds)
    delivered["cmd_vel"] = received / commands_sent if commands_sent else 0.0
    in_window: float = sum(after[t] - before[t] for t in after if t != "cmd_vel")
    in_window += (after["cmd_vel"] - before["cmd_vel"]) * delivered["cmd_vel"]
    schedule = (total_offered(robots) - offered_rate(robots, "cmd_vel")) * simulated
    return Round(
        robots,
        ceiling=False,
        window_s=measured.seconds,
        cpu=measured.cpu,
        delivered=delivered,
        messages=in_window,
        threads=measured.threads,
        rss=measured.rss,
        startup_s=None if flowing is None else flowing - started,
        silent=silent,
        silent_status=silent_status,
        sub_cpu=measured.sub_cpu,
        simulator_share=sum(sent) / schedule,
    )


def _numbers(proc: PeerProcess, prefix: str) -> list[int]:
    """The last word of every line of ``proc`` starting with ``prefix``, as an integer."""
    return [int(line.split()[-1]) for line in proc.output().splitlines() if line.startswith(prefix)]


def ceiling_round(robots: int, seconds: float, env: Mapping[str, str]) -> Round:
    """The same ROS topics from one rclpy publisher process to the same subscriber."""
    sub = _start_subscriber(robots, env)
    command = [sys.executable, "-m", "benchmarks.fleet_ros", "pub", str(robots)]
    publisher = start_process(command, env)
    silent = _wait_flowing(sub)[1]
    time.sleep(SETTLE)
    measured = _window(sub, publisher, seconds)
    return Round(
        robots,
        ceiling=True,
        window_s=measured.seconds,
        cpu=measured.cpu,
        delivered=_delivered(robots, measured.before, measured.after, measured.seconds),
        messages=sum(
            measured.after[t] - measured.before[t] for t in measured.after if t != "cmd_vel"
        ),
        threads=measured.threads,
        rss=measured.rss,
        sub_cpu=measured.sub_cpu,
        silent=silent,
    )


@dataclass(frozen=True)
class Window:
    """One measured window of a round."""

    seconds: float
    before: dict[str, int]
    after: dict[str, int]
    cpu: float
    sub_cpu: float
    threads: int
    rss: float


def idle_round(robots: int, seconds: float) -> Idle:
    """The fleet's bridge alone, no simulator, no subscriber: CPU over ``seconds``."""
    print(f"== idle bridge of {robots} robots", file=sys.stderr)
    env = {**run_env(), "PYTHONPATH": str(ROOT)}
    names = fleet_sim.robots(robots)
    try:
        bridge = start_process(
            [str(BIN / "parameter_bridge"), *fleet_sim.bridge_arguments(names)], env
        )
        time.sleep(IDLE_SETTLE)
        window = CpuWindow(bridge.pid)
        window.begin()
        time.sleep(seconds)
        window.end()
        result = Idle(robots, window.percent or 0.0, threads_of(bridge), rss_mb(bridge.pid))
    finally:
        stop_all()
    print(result, file=sys.stderr, flush=True)
    return result


def run(robots: int, seconds: float, ceiling: bool) -> Round:
    """One round; a round that fails is reported with its error and the others go on."""
    print(f"== fleet of {robots}, {'ceiling' if ceiling else 'bridge'}", file=sys.stderr)
    try:
        measure = ceiling_round if ceiling else bridge_round
        result = measure(robots, seconds, run_env())
    except FlowFailure as error:  # reported in the table instead
        first = (str(error).strip().splitlines() or [type(error).__name__])[0]
        result = Round(robots, ceiling, error=first[:160])
    finally:
        stop_all()
    print(result, file=sys.stderr, flush=True)
    return result

"""A fleet in one bridge process (issue 28, item 6): CPU, delivery, threads, memory, start-up.

Usage: ``.venv/bin/python -m benchmarks.fleet [--robots 10 25 50] [--seconds 20]``.

Per fleet size N: the C++ peer on Ignition Transport 11 plays the simulator (mode
``pub-fleet``: one process, one node, publishing ``/clock`` at 1 kHz and each robot's odom
50 Hz, imu 200 Hz and joint_states 100 Hz whether or not anyone subscribes, and subscribed to
each robot's ``cmd_vel``; ``testing/fleet_sim.py``). One ``parameter_bridge`` with
``config/fleet_bridge.yaml`` and ``robot=robot_1,...`` (1 + 4N entries). One rclpy process
(``benchmarks.fleet_ros sub``) takes every ROS topic serialized and counts per topic, and
publishes every robot's ``cmd_vel`` at 10 Hz. Measured: start-up (from just before the bridge
process starts to every topic having brought a message to that subscriber; the simulator is
already publishing), then over ``--seconds`` the bridge's CPU (``/proc/<pid>/stat``), what
arrived per topic kind against what the schedule offered, the bridge's threads and RSS at the
end. ``cmd_vel``: what the simulator received of what the subscriber sent over the whole run.
Beside it, the same run's rclpy ceiling: one rclpy process (``benchmarks.fleet_ros pub``)
publishing the same ROS topics at the same rates, each message serialized once, with no
Gazebo side and no conversion, to the same subscriber. Last, the largest fleet's bridge alone
(no simulator, no subscriber): its CPU at rest. The C++ bridge is not installable here: its
figures are quoted from issue 28.
"""

from __future__ import annotations

import argparse
import json
import os
import signal
import statistics
import sys
import time
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

from benchmarks.harness import BIN, ROOT, CpuWindow, FlowFailure, stop_all
from benchmarks.report import write_section
from benchmarks.results import store
from testing import fleet_sim
from testing.e2e_harness import status_rows
from testing.gzpeer import PeerProcess, start_peer, start_process, wait_for_line
from testing.procstat import rss_mb, threads_of
from testing.run_env import run_env

#: Where the quoted figures come from.
QUOTED = "quoted from issue 28 (2026-11-28), measured by its author on 2 cores, not here"
#: Topic kinds of the delivery columns, Gazebo -> ROS first.
KINDS = ("clock", *(kind.name for kind in fleet_sim.KINDS), "cmd_vel")
#: Seconds between every topic flowing and the measured window (late matches settle).
SETTLE = 2.0
#: Longest wait for every topic to flow after the bridge started.
FLOW_TIMEOUT = 120.0
#: Issue 28's goals.
GOAL_CPU_RATIO = 0.8
GOAL_FLAT = 0.15
GOAL_THREADS = 20
GOAL_STARTUP_ROBOTS, GOAL_STARTUP_S = 25, 2.6
GOAL_DELIVERED = 0.99
GOAL_IDLE_PERCENT, GOAL_IDLE_ENTRIES = 1.0, 100
#: Seconds between an idle bridge's start and its measured window (its channels exist).
IDLE_SETTLE = 5.0


@dataclass(frozen=True)
class Quoted:
    """One row of issue 28's table: the C++ bridge's figures (and ours of then)."""

    #: Messages a second the issue's fleet offered (its own count).
    offered: float
    cpu_cpp: float
    cpu_ours: float
    startup_cpp: tuple[float, float]
    delivered_cpp: tuple[float, float]
    threads_cpp: int
    rss_cpp: float

    def cpp_us_per_message(self) -> float:
        """CPU time per delivered message of the C++ bridge, from the issue's offered rate
        and the middle of its delivered range."""
        delivered = self.offered * statistics.mean(self.delivered_cpp)
        return self.cpu_cpp / 100 / delivered * 1e6


ISSUE_28 = {
    10: Quoted(4_500, 35.1, 38.6, (1.8, 4.6), (1.0, 1.0), 20, 138),
    25: Quoted(11_000, 54.3, 61.9, (2.6, 2.6), (0.96, 1.0), 20, 145),
    50: Quoted(22_000, 46.7, 60.6, (4.8, 4.8), (0.60, 0.69), 20, 151),
}


def offered_rate(robots: int, kind: str) -> float:
    """Messages a second the fleet offers on every topic of ``kind`` together."""
    if kind == "clock":
        return fleet_sim.CLOCK_HZ
    if kind == "cmd_vel":
        return fleet_sim.CMD_VEL_HZ * robots
    return next(k.hz for k in fleet_sim.KINDS if k.name == kind) * robots


def total_offered(robots: int) -> float:
    return sum(offered_rate(robots, kind) for kind in KINDS)


@dataclass(frozen=True)
class Round:
    """One fleet size through the bridge (or, with ``ceiling``, the bare rclpy publisher)."""

    robots: int
    ceiling: bool
    window_s: float = 0.0
    #: CPU of the bridge (the ceiling: of the rclpy publisher), % of one core.
    cpu: float = 0.0
    #: Delivered share per kind (:data:`KINDS`).
    delivered: dict[str, float] = field(default_factory=dict)
    #: Messages delivered in the window, both directions.
    messages: float = 0.0
    threads: int = 0
    rss: float = 0.0
    #: Seconds to every topic flowing; None when some never did (``silent``).
    startup_s: float | None = 0.0
    silent: tuple[str, ...] = ()
    #: The bridge's status rows of the silent topics.
    silent_status: tuple[str, ...] = ()
    sub_cpu: float = 0.0
    #: What the simulator sent of its schedule (the bridge rounds).
    simulator_share: float = 0.0
    error: str = ""

    @property
    def us_per_message(self) -> float:
        return self.cpu / 100 * self.window_s / self.messages * 1e6 if self.messages else 0.0


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


@dataclass(frozen=True)
class Idle:
    """The bridge of a fleet's YAML with nothing on either side: its own cost at rest."""

    robots: int
    cpu: float
    threads: int
    rss: float

    @property
    def entries(self) -> int:
        return 1 + 4 * self.robots


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


def _percent(share: float) -> str:
    return f"{100 * share:.1f}%"


def _delivered_cell(row: Round) -> str:
    return " / ".join(_percent(row.delivered[kind]) for kind in KINDS if kind in row.delivered)


def _startup_cell(row: Round) -> str:
    if row.startup_s is not None:
        return f"{row.startup_s:.2f} s"
    examples = " ".join(row.silent[:3])
    return f"> {FLOW_TIMEOUT:g} s: {len(row.silent)} topics never flowed ({examples} ...)"


def _quoted_cell(low: float, high: float, *, unit: str = "") -> str:
    return f"{low:g}{unit}" if low == high else f"{low:g}-{high:g}{unit}"


def goal_lines(rows: Sequence[Round], idle: Idle | None = None) -> list[str]:
    """Issue 28's goals, each judged on this run's rows."""
    bridge = {row.robots: row for row in rows if not row.ceiling and not row.error}
    lines = []

    def judge(goal: str, met: bool | None, figure: str) -> None:
        verdict = "not measured" if met is None else ("**met**" if met else "**missed**")
        lines.append(f"- {goal}: {figure} — {verdict}")

    for robots, measured in bridge.items():
        quoted = ISSUE_28.get(robots)
        if quoted is None:
            continue
        cpp = quoted.cpp_us_per_message()
        judge(
            f"CPU per delivered message at {robots} robots <= {GOAL_CPU_RATIO:g}x C++ "
            f"({GOAL_CPU_RATIO * cpp:.1f} µs; C++ {cpp:.1f} µs, derived from the quoted CPU and "
            "the middle of its delivered range)",
            measured.us_per_message <= GOAL_CPU_RATIO * cpp,
            f"{measured.us_per_message:.1f} µs",
        )
    smallest, largest = min(bridge, default=0), max(bridge, default=0)
    if smallest != largest:
        low, high = bridge[smallest].us_per_message, bridge[largest].us_per_message
        judge(
            f"flat: {largest} robots within {GOAL_FLAT:.0%} of {smallest} per message, either way",
            abs(high / low - 1) <= GOAL_FLAT,
            f"{high:.1f} vs {low:.1f} µs ({high / low - 1:+.0%})",
        )
    most = max((row.threads for row in bridge.values()), default=None)
    judge(
        f"threads <= {GOAL_THREADS} for any fleet",
        None if most is None else most <= GOAL_THREADS,
        f"at most {most}",
    )
    row = bridge.get(GOAL_STARTUP_ROBOTS)
    judge(
        f"start-up at {GOAL_STARTUP_ROBOTS} robots <= C++ ({GOAL_STARTUP_S:g} s)",
        None if row is None else row.startup_s is not None and row.startup_s <= GOAL_STARTUP_S,
        "-" if row is None else _startup_cell(row),
    )
    judge(
        f"delivered >= {GOAL_DELIVERED:.0%} per kind at {GOAL_STARTUP_ROBOTS} robots",
        None if row is None else min(row.delivered.values()) >= GOAL_DELIVERED,
        "-" if row is None else _delivered_cell(row),
    )
    largest_row = bridge.get(50)
    judge(
        f"/clock >= {GOAL_DELIVERED:.0%} at 50 robots",
        None if largest_row is None else largest_row.delivered["clock"] >= GOAL_DELIVERED,
        "-" if largest_row is None else _percent(largest_row.delivered["clock"]),
    )
    if idle is not None:
        judge(
            f"an idle bridge of {GOAL_IDLE_ENTRIES}+ entries < {GOAL_IDLE_PERCENT:g}% of a core",
            idle.entries >= GOAL_IDLE_ENTRIES and idle.cpu < GOAL_IDLE_PERCENT,
            f"{idle.cpu:.2f}% ({idle.entries} entries)",
        )
    return lines


def report(
    rows: Sequence[Round], idle: Idle | None, args: argparse.Namespace, load: float, plot: str
) -> str:
    robots = " ".join(str(n) for n in args.robots)
    lines = [
        "## A fleet in one process (issue 28)",
        "",
        f"Command: `.venv/bin/python -m benchmarks.fleet --robots {robots} --seconds "
        f"{args.seconds:g}`. 1-minute load average before the run: {load:.2f}; the machine "
        "(2 cores) is shared with other work, so every figure is noisy.",
        "",
        "The simulator is the C++ peer on Ignition Transport 11 (`testing/peer`, mode `pub-fleet`: "
        "one process, one node) publishing `/clock` at 1 kHz and per robot odom 50 Hz, imu "
        "200 Hz, joint_states 100 Hz (two joints), whether or not anyone subscribes, each "
        "message serialized once; it subscribes to every robot's `cmd_vel`. One "
        "`parameter_bridge` with `config/fleet_bridge.yaml` (1 + 4N entries). One rclpy process "
        "subscribes to every ROS topic taking the messages serialized (`raw=True`), counts per "
        "topic, and publishes each robot's `cmd_vel` at 10 Hz. Start-up: from just before the "
        "bridge process starts to every topic having brought a message to that subscriber. "
        f"Then a window of {args.seconds:g} s: the bridge's CPU (`/proc/<pid>/stat`, % of one "
        "core) and per delivered message (both directions), delivered per kind against the "
        "schedule (`cmd_vel`: received by the simulator of what the subscriber sent, whole "
        "run), threads and RSS at the end, the subscriber's own CPU, and the share of its "
        "schedule the simulator kept. Shares are of the nominal schedule, so a window can "
        "show a little over 100%. Where the ceiling below loses the same kind, the limit is "
        "the one rclpy subscriber (reliable, keep-last 10: at 1 kHz, `/clock` overwrites what "
        "it has not taken), not the bridge.",
        "",
        "| robots (entries) | offered msg/s | bridge CPU | µs CPU / delivered msg | start-up s "
        "| delivered clock / odom / imu / joint_states / cmd_vel | threads | RSS MB "
        "| subscriber CPU | simulator kept |",
        "|---|---|---|---|---|---|---|---|---|---|",
    ]
    for row in rows:
        if row.ceiling:
            continue
        head = f"| {row.robots} ({1 + 4 * row.robots}) | {total_offered(row.robots):,.0f} "
        if row.error:
            lines.append(head + f"| failed: {row.error} |" + " |" * 7)
            continue
        lines.append(
            head + f"| {row.cpu:.1f}% | {row.us_per_message:.1f} | {_startup_cell(row)} "
            f"| {_delivered_cell(row)} | {row.threads} | {row.rss:.0f} | {row.sub_cpu:.1f}% "
            f"| {_percent(row.simulator_share)} |"
        )
    for row in rows:
        if row.silent_status:
            lines += [
                "",
                f"The bridge's status of the topics that never flowed ({row.robots} robots):",
            ]
            lines += ["", "```", *row.silent_status, "```"]
    lines += [
        "",
        "The same run's rclpy ceiling: one rclpy process publishing the same ROS topics at the "
        "same rates (each message serialized once, no Gazebo side, no conversion) to the same "
        "subscriber: what one rclpy process pays for the fleet's ROS traffic alone.",
        "",
        "| robots | rclpy publisher CPU | µs CPU / delivered msg | delivered clock / odom / imu "
        "/ joint_states | threads | RSS MB | subscriber CPU |",
        "|---|---|---|---|---|---|---|",
    ]
    for row in rows:
        if not row.ceiling:
            continue
        if row.error:
            lines.append(f"| {row.robots} | failed: {row.error} |" + " |" * 5)
            continue
        lines.append(
            f"| {row.robots} | {row.cpu:.1f}% | {row.us_per_message:.1f} | {_delivered_cell(row)} "
            f"| {row.threads} | {row.rss:.0f} | {row.sub_cpu:.1f}% |"
        )
    lines += [
        "",
        f"Issue 28's table ({QUOTED}): the C++ bridge beside ours of then.",
        "",
        "| robots | offered msg/s (the issue's count) | CPU C++ (ours then) "
        "| µs CPU / delivered msg, C++ | start-up s, C++ | delivered, C++ | threads, C++ "
        "| RSS MB, C++ |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for count, quoted in ISSUE_28.items():
        lines.append(
            f"| {count} | ~{quoted.offered:,.0f} | {quoted.cpu_cpp:g}% ({quoted.cpu_ours:g}%) "
            f"| {quoted.cpp_us_per_message():.1f} "
            f"| {_quoted_cell(*quoted.startup_cpp)} "
            f"| {_quoted_cell(*[100 * d for d in quoted.delivered_cpp], unit='%')} "
            f"| {quoted.threads_cpp} | {quoted.rss_cpp:g} |"
        )
    if idle is not None:
        lines += [
            "",
            f"At rest: the bridge of the {idle.robots}-robot YAML ({idle.entries} entries, the "
            "Gazebo -> ROS ones and `cmd_vel` ROS -> Gazebo native) with no simulator and no "
            f"subscriber, measured over {args.idle_seconds:g} s after {IDLE_SETTLE:g} s: "
            f"**{idle.cpu:.2f}% of a core**, {idle.threads} threads, {idle.rss:.0f} MB.",
        ]
    lines += [
        "",
        "Issue 28's goals, on this run:",
        "",
        *goal_lines(rows, idle),
        "",
        f"![fleet]({plot})",
    ]
    return "\n".join(lines)


def numbers(rows: Sequence[Round], idle: Idle | None = None) -> dict[str, float]:
    """This run's figures for ``benchmarks/results.json`` (``fleet<N>.<figure>``; the
    ceiling's as ``ceiling<N>.<figure>``; the idle bridge's as ``idle<N>.<figure>``)."""
    stored: dict[str, float] = {}
    if idle is not None:
        key = f"idle{idle.robots}"
        stored |= {
            f"{key}.cpu_percent": round(idle.cpu, 3),
            f"{key}.threads": idle.threads,
            f"{key}.rss_mb": round(idle.rss, 1),
        }
    for row in rows:
        if row.error:
            continue
        key = f"{'ceiling' if row.ceiling else 'fleet'}{row.robots}"
        stored |= {
            f"{key}.cpu_percent": round(row.cpu, 2),
            f"{key}.us_per_message": round(row.us_per_message, 2),
            f"{key}.threads": row.threads,
            f"{key}.rss_mb": round(row.rss, 1),
            f"{key}.subscriber_cpu_percent": round(row.sub_cpu, 2),
            **{f"{key}.delivered.{k}": round(v, 4) for k, v in row.delivered.items()},
        }
        if not row.ceiling:
            if row.startup_s is not None:
                stored[f"{key}.startup_s"] = round(row.startup_s, 3)
            stored[f"{key}.silent_topics"] = len(row.silent)
            stored[f"{key}.simulator_share"] = round(row.simulator_share, 4)
    return stored


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--robots", type=int, nargs="+", default=[10, 25, 50])
    parser.add_argument("--seconds", type=float, default=20.0)
    parser.add_argument(
        "--idle-seconds", type=float, default=20.0, help="the idle bridge's window; 0: none"
    )
    args = parser.parse_args(argv)
    load = os.getloadavg()[0]
    rows = [run(count, args.seconds, ceiling) for count in args.robots for ceiling in (False, True)]
    idle = idle_round(max(args.robots), args.idle_seconds) if args.idle_seconds > 0 else None
    store("fleet", {}, load, numbers(rows, idle))
    from benchmarks.plots import fleet_plot  # noqa: PLC0415 - matplotlib, the bench extra

    plot = fleet_plot(rows, ISSUE_28)
    write_section("fleet", report(rows, idle, args, load, plot))
    return 0


if __name__ == "__main__":
    sys.exit(main())

"""What a fleet round measures, the goals it is judged by, and the C++ bridge's figures quoted
as the bar (``benchmarks.fleet`` runs the rounds and writes the section; ``benchmarks.plots``
draws them)."""

from __future__ import annotations

import statistics
from collections.abc import Sequence
from dataclasses import dataclass, field

from testing import fleet_sim

#: Where the quoted figures come from.
QUOTED = "quoted from issue 28 (2026-11-28), measured by its author on 2 cores, not here"
#: Topic kinds of the delivery columns, Gazebo -> ROS first.
KINDS = ("clock", *(kind.name for kind in fleet_sim.KINDS), "cmd_vel")
#: Longest wait for every topic to flow after the bridge started.
FLOW_TIMEOUT = 120.0
#: The goals.
GOAL_CPU_RATIO = 0.8
GOAL_FLAT = 0.15
GOAL_THREADS = 20
GOAL_STARTUP_ROBOTS, GOAL_STARTUP_S = 25, 2.6
GOAL_DELIVERED = 0.99
GOAL_IDLE_PERCENT, GOAL_IDLE_ENTRIES = 1.0, 100


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


#: The C++ bridge's figures by fleet size.
CPP_QUOTED = {
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


def percent(share: float) -> str:
    return f"{100 * share:.1f}%"


def delivered_cell(row: Round) -> str:
    return " / ".join(percent(row.delivered[kind]) for kind in KINDS if kind in row.delivered)


def startup_cell(row: Round) -> str:
    if row.startup_s is not None:
        return f"{row.startup_s:.2f} s"
    examples = " ".join(row.silent[:3])
    return f"> {FLOW_TIMEOUT:g} s: {len(row.silent)} topics never flowed ({examples} ...)"


def quoted_cell(low: float, high: float, *, unit: str = "") -> str:
    return f"{low:g}{unit}" if low == high else f"{low:g}-{high:g}{unit}"


def goal_lines(rows: Sequence[Round], idle: Idle | None = None) -> list[str]:
    """Issue 28's goals, each judged on this run's rows."""
    bridge = {row.robots: row for row in rows if not row.ceiling and not row.error}
    lines = []

    def judge(goal: str, met: bool | None, figure: str) -> None:
        verdict = "not measured" if met is None else ("**met**" if met else "**missed**")
        lines.append(f"- {goal}: {figure} — {verdict}")

    for robots, measured in bridge.items():
        quoted = CPP_QUOTED.get(robots)
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
        "-" if row is None else startup_cell(row),
    )
    judge(
        f"delivered >= {GOAL_DELIVERED:.0%} per kind at {GOAL_STARTUP_ROBOTS} robots",
        None if row is None else min(row.delivered.values()) >= GOAL_DELIVERED,
        "-" if row is None else delivered_cell(row),
    )
    largest_row = bridge.get(50)
    judge(
        f"/clock >= {GOAL_DELIVERED:.0%} at 50 robots",
        None if largest_row is None else largest_row.delivered["clock"] >= GOAL_DELIVERED,
        "-" if largest_row is None else percent(largest_row.delivered["clock"]),
    )
    if idle is not None:
        judge(
            f"an idle bridge of {GOAL_IDLE_ENTRIES}+ entries < {GOAL_IDLE_PERCENT:g}% of a core",
            idle.entries >= GOAL_IDLE_ENTRIES and idle.cpu < GOAL_IDLE_PERCENT,
            f"{idle.cpu:.2f}% ({idle.entries} entries)",
        )
    return lines

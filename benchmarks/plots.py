"""The PNG plots of BENCHMARKS.md and its reports, drawn from ``benchmarks/results.json``
(matplotlib, Agg).

matplotlib comes with the ``bench`` extra (``pip install '.[bench]'``, which ``make bench``
does); it is imported only inside the functions that draw, so nothing else needs it.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING

from benchmarks.costs import (
    GZ_TO_ROS,
    ROS_TO_GZ,
    SPLIT_GROUPS,
    flow_key,
    per_message_ms,
    thread_split_ms,
)
from benchmarks.fleet_goals import CPP_CEILING_RATIO, GOAL_RATIO, Round, sizes
from benchmarks.harness import PYTHON_THREADS
from benchmarks.reference import CPU_PER_MESSAGE, QUOTED, SUSTAINED_P99_MS, cpu_goal_ms
from benchmarks.results import COSTS_PNG, FLEET_PNG, SUSTAINED_PNG, Stored
from benchmarks.sustained import side_flows
from benchmarks.tables import SIZES

if TYPE_CHECKING:
    from matplotlib.figure import Figure

ROOT = Path(__file__).resolve().parent.parent
#: The bars of the CPU plot: the bridge (split by thread group where measured), then the rclpy
#: ends of the ceiling flow.
BARS = ("bridge", "rclpy publisher", "rclpy subscriber")


def _agg() -> None:
    import matplotlib  # noqa: PLC0415 - the optional bench extra, only when drawing

    matplotlib.use("Agg")


def sustained_plot(stored: Stored) -> str:
    """Delivered rate and p99 latency against the offered rate, bridge and ceiling."""
    _agg()
    import matplotlib.pyplot as plt  # noqa: PLC0415

    figure, (rates, latencies) = plt.subplots(2, 1, sharex=True, figsize=(7, 6.5))
    top = 0.0
    for side, style, label in (
        ("bridge", "o-", "parameter_bridge, Gazebo -> ROS"),
        ("ceiling", "s--", "ceiling: rclpy -> rclpy"),
    ):
        flows = {hz: flow for hz, flow in side_flows(stored, side).items() if not flow.error}
        offered = list(flows)
        top = max([top, *offered])
        rates.plot(offered, [flow.rate for flow in flows.values()], style, label=label)
        latencies.plot(offered, [flow.p99_us / 1000 for flow in flows.values()], style, label=label)
    rates.plot([0, top], [0, top], ":", color="grey", label="delivered = offered")
    latencies.axhline(SUSTAINED_P99_MS, color="grey", linestyle=":", label="sustainable limit")
    rates.set_ylabel("delivered frames/s")
    latencies.set_ylabel("p99 latency, ms")
    latencies.set_xlabel("offered rate, Hz (1920x1080 rgb8 images)")
    rates.set_title(f"1080p Gazebo -> ROS ({stored.when}, load {stored.load_before:.2f})")
    for axes in (rates, latencies):
        axes.grid(alpha=0.3)
        axes.legend(fontsize=8)
    return _save(figure, SUSTAINED_PNG)


def _costs(stored: Stored, way: str, kind: str, hz: float) -> list[float]:
    """The bars of one case, ms per message (0 where not measured)."""
    flow, ceiling = stored.flow(flow_key(way, kind, hz)), stored.flow(flow_key("ceiling", kind, hz))
    values = [per_message_ms(flow.cpu, hz, flow) if flow else None]
    if ceiling is not None:
        values += [per_message_ms(cpu, hz, ceiling) for cpu in (ceiling.pub_cpu, ceiling.sub_cpu)]
    return [value or 0.0 for value in values] + [0.0] * (len(BARS) - len(values))


def costs_plot(stored: Stored) -> str:
    """CPU per delivered message per type and direction: the bridge, the rclpy ends of the
    same rate, and the quoted C++ bar."""
    _agg()
    import matplotlib.pyplot as plt  # noqa: PLC0415

    cases = [("GZ->ROS", kind, hz) for kind, hz in GZ_TO_ROS]
    cases += [("ROS->GZ", kind, hz) for kind, hz in ROS_TO_GZ]
    labels = [f"{SIZES[kind]} {way} {hz / 1000:g} kHz" for way, kind, hz in cases]
    values = [_costs(stored, *case) for case in cases]
    figure, axes = plt.subplots(figsize=(8, 0.6 * len(cases) + 1.5))
    height = 0.27
    left = [0.0] * len(cases)
    segments = _bridge_segments(stored, cases, [case[0] for case in values])
    colours = ("tab:blue", "navy", "tab:cyan")
    positions = [i - height for i in range(len(cases))]
    for (name, widths), colour in zip(segments.items(), colours, strict=False):
        axes.barh(positions, widths, height=height, left=left, color=colour, label=name)
        left = [a + b for a, b in zip(left, widths, strict=True)]
    for bar, (name, colour) in enumerate(zip(BARS[1:], ("tab:orange", "tab:green"), strict=True)):
        positions = [i + bar * height for i in range(len(cases))]
        widths = [case[bar + 1] for case in values]
        axes.barh(positions, widths, height=height, color=colour, label=name)
    quoted = [
        (i - height, cpu_goal_ms(CPU_PER_MESSAGE[key[1], key[0], key[2]]))
        for i, key in enumerate(cases)
        if (key[1], key[0], key[2]) in CPU_PER_MESSAGE
    ]
    if quoted:
        axes.scatter(
            [ms for _, ms in quoted], [at for at, _ in quoted], marker="|", s=300, color="black",
            label=f"C++ bridge, the goal ({QUOTED})",
        )  # fmt: skip
    axes.set_yticks(range(len(cases)), labels, fontsize=8)
    axes.invert_yaxis()
    axes.set_xlabel("CPU time per delivered message, ms")
    axes.set_title(f"CPU per message ({stored.when}, load {stored.load_before:.2f})")
    axes.grid(axis="x", alpha=0.3)
    axes.legend(fontsize=7, loc="lower right")
    return _save(figure, COSTS_PNG)


def _bridge_segments(
    stored: Stored, cases: list[tuple[str, str, float]], totals: list[float]
) -> dict[str, list[float]]:
    """The bridge's bar of each case split by thread group where measured (each group's share
    of the threads' run time, of the process's CPU per message), by label."""
    shares = []
    for way, kind, hz in cases:
        flow = stored.flow(flow_key(way, kind, hz))
        split = None if flow is None else thread_split_ms(hz, flow)
        total = sum(split.values()) if split else 0.0
        shares.append({g: ms / total for g, ms in split.items()} if split and total else None)
    if not any(shares):
        return {"bridge": totals}
    return {
        f"bridge: {group} threads": [
            total * (share[group] if share else float(group == PYTHON_THREADS))
            for total, share in zip(totals, shares, strict=True)
        ]
        for group in SPLIT_GROUPS
    }


def native_overload_plot(series: Mapping[str, Sequence[tuple[float, float]]], relative: str) -> str:
    """Delivered against offered rate (kHz) of ``benchmarks.native_plane``'s overload sweep
    (``series``: label -> points), with the delivered = offered line."""
    _agg()
    import matplotlib.pyplot as plt  # noqa: PLC0415

    figure, axes = plt.subplots(figsize=(7, 4.5))
    top = max((offered for points in series.values() for offered, _ in points), default=1.0)
    # One colour per path, one marker per subscriber; delivered solid, published dashed.
    for label, points in series.items():
        colour = "tab:blue" if label.startswith("native") else "tab:orange"
        style = ("^" if "serialized" in label else "o") + ("--" if "published" in label else "-")
        axes.plot([p[0] for p in points], [p[1] for p in points], style, color=colour, label=label)
    axes.plot([0, top], [0, top], ":", color="grey", label="delivered = offered")
    axes.set_xlabel("offered rate, kHz (Odometry, Gazebo -> ROS)")
    axes.set_ylabel("kHz")
    axes.set_title("The native data plane under overload")
    axes.grid(alpha=0.3)
    axes.legend(fontsize=8)
    return _save(figure, relative)


def fleet_plot(rows: Sequence[Round]) -> str:
    """``benchmarks.fleet`` against the number of robots: CPU per delivered message of the
    bridge and of the same run's rclpy ceiling, their ratio round by round against the goal,
    the worst delivered share and ``/clock``'s, and the peak RSS, each side by side."""
    _agg()
    import matplotlib.pyplot as plt  # noqa: PLC0415

    measured = [size for size in sizes(rows) if size.measured]
    robots = [size.robots for size in measured]
    figure, axes = plt.subplots(2, 2, figsize=(9, 6.5))
    cpu, ratio, delivered, memory = axes.flat
    cpu.plot(robots, [size.us for size in measured], "o-", label="parameter_bridge")
    cpu.plot(robots, [size.ceiling_us for size in measured], "s--", label="rclpy ceiling")
    cpu.set_ylabel("µs CPU per delivered message (median)")
    for size in measured:
        pairs = size.pair_ratios()
        ratio.plot([size.robots] * len(pairs), pairs, "o", color="tab:blue", alpha=0.5)
    ratio.plot(robots, [size.ratio for size in measured], "o-", label="bridge / ceiling")
    ratio.axhline(GOAL_RATIO, color="grey", linestyle=":", label=f"goal: {GOAL_RATIO:g}x")
    ratio.axhline(
        CPP_CEILING_RATIO, color="black", linestyle=":", label="C++ bridge (issue 36, quoted)"
    )
    ratio.set_ylabel("bridge / ceiling, per delivered message")
    for ceiling, style, colour, side in (
        (False, "o-", "tab:blue", "bridge"),
        (True, "s--", "tab:orange", "ceiling"),
    ):
        delivered.plot(
            robots, [100 * size.worst(ceiling) for size in measured], style, color=colour,
            label=f"{side}, worst kind in any round",
        )  # fmt: skip
        delivered.plot(
            robots, [100 * size.delivered(ceiling)["clock"] for size in measured], style,
            color=colour, alpha=0.4, label=f"{side}, /clock (median)",
        )  # fmt: skip
    delivered.set_ylabel("delivered, % of offered")
    memory.plot(
        robots, [max(r.rss_peak for r in size.bridge) for size in measured], "o-",
        label="parameter_bridge",
    )  # fmt: skip
    memory.plot(
        robots, [max(r.rss_peak for r in size.ceiling) for size in measured], "s--",
        label="rclpy ceiling",
    )  # fmt: skip
    memory.set_ylabel("peak RSS, MB")
    for axes_ in axes.flat:
        axes_.set_xlabel("robots")
        axes_.grid(alpha=0.3)
        axes_.legend(fontsize=7)
    figure.suptitle("A fleet through one bridge process, against the same run's rclpy ceiling")
    return _save(figure, FLEET_PNG)


def _save(figure: Figure, relative: str) -> str:
    import matplotlib.pyplot as plt  # noqa: PLC0415

    path = ROOT / relative
    path.parent.mkdir(parents=True, exist_ok=True)
    figure.tight_layout()
    figure.savefig(path, dpi=100, metadata={"Software": None})
    plt.close(figure)
    return relative

"""1080p images Gazebo -> ROS at rising offered rates: what arrives, how late, and the highest
sustainable rate, beside rclpy -> rclpy at the same rates (issue 15).

Usage: ``.venv/bin/python -m benchmarks.sustained [--seconds S] [--rates HZ ...]``; writes the
report ``benchmarks/reports/sustained.md`` and stores its flows for the headline and the plots.
A rate is sustainable when >= 99% of the frames arrive with a p99 latency under 100 ms.
"""

from __future__ import annotations

import argparse
import os
import sys

from benchmarks.bridged import backend, ceilings, through_bridge
from benchmarks.costs import per_message_ms
from benchmarks.harness import GZ_ENDS, FlowResult
from benchmarks.reference import (
    CPU_PER_FRAME_30HZ,
    GOAL_CPU_PER_FRAME_30HZ_MS,
    GOAL_LATENCY_30HZ_MS,
    GOAL_SUSTAINED_HZ,
    LATENCY_30HZ,
    QUOTED,
    SUSTAINED_1080P,
    SUSTAINED_P99_MS,
    SUSTAINED_SHARE,
)
from benchmarks.report import link, write_section
from benchmarks.results import SUSTAINED_PNG, Stored, store
from benchmarks.tables import verdict

RATES = (30.0, 60.0, 90.0, 120.0, 150.0, 180.0)
KIND = "image1080"
#: The rate the latency and CPU-per-frame goals are judged at.
PACED_HZ = 30.0
#: The side the uncounted first flow through the fresh bridge is stored under.
WARM_UP = "warm-up"
HEADER = (
    "| offered | bridge msg/s | delivered/sent | median ms | p99 ms | bridge CPU "
    "| bridge CPU per frame, ms | sustainable | ceiling msg/s | delivered/sent | median ms "
    "| p99 ms | sustainable |\n|---|---|---|---|---|---|---|---|---|---|---|---|---|"
)


def sustainable(result: FlowResult) -> bool:
    """>= 99% of the frames arrived, with a p99 latency under 100 ms."""
    return (
        not result.error
        and result.share >= SUSTAINED_SHARE
        and result.p99_us < SUSTAINED_P99_MS * 1000
    )


def highest(results: dict[float, FlowResult]) -> float | None:
    """The highest offered rate up to which every offered rate was sustainable (None: not
    even the lowest)."""
    best = None
    for hz in sorted(results):
        if not sustainable(results[hz]):
            break
        best = hz
    return best


def flow_key(side: str, hz: float) -> str:
    """The name a flow is stored under: ``bridge 30``, ``ceiling 30`` or ``warm-up 30``."""
    return f"{side} {hz:g}"


def side_flows(stored: Stored, side: str) -> dict[float, FlowResult]:
    """The stored flows of one side (``bridge``, ``ceiling`` or ``warm-up``), by offered rate."""
    flows = {}
    for key, flow in stored.flows.items():
        name, _, hz = key.partition(" ")
        if name == side:
            flows[float(hz)] = flow
    return dict(sorted(flows.items()))


def _cells(result: FlowResult) -> str:
    if result.error:
        return f"failed: {result.error} ||||"
    return (
        f"{result.rate:,.1f} | {result.received}/{result.sent} | {result.median_us / 1000:.2f} "
        f"| {result.p99_us / 1000:.2f}"
    )


def _row(hz: float, bridge: FlowResult, ceiling: FlowResult) -> str:
    cpu = "-" if bridge.cpu is None else f"{bridge.cpu:.0f}%"
    per_frame = per_message_ms(bridge.cpu, hz, bridge)
    frame = "-" if per_frame is None else f"{per_frame:.2f}"
    verdicts = ["yes" if sustainable(result) else "no" for result in (bridge, ceiling)]
    return (
        f"| {hz:g} Hz | {_cells(bridge)} | {cpu} | {frame} | {verdicts[0]} "
        f"| {_cells(ceiling)} | {verdicts[1]} |"
    )


def _rate_text(rate: float | None, rates: list[float]) -> str:
    if rate is None:
        return f"below {min(rates):g} Hz"
    return f"{rate:g} Hz" + (" (the highest offered)" if rate == max(rates) else "")


def goals(bridge: dict[float, FlowResult], ceiling: dict[float, FlowResult]) -> list[str]:
    rates = sorted(bridge)
    best = highest(bridge)
    reached = best is not None and best >= GOAL_SUSTAINED_HZ
    short = f"{GOAL_SUSTAINED_HZ - (best or 0):g} Hz (next offered rate failed)"
    lines = [
        f"- Highest sustainable rate >= {GOAL_SUSTAINED_HZ:g} Hz: {_rate_text(best, rates)} "
        f"(ceiling: {_rate_text(highest(ceiling), rates)}) — {verdict(reached, short)}. The C++ "
        f"bridge: {SUSTAINED_1080P.cpp_text()} ({QUOTED})."
    ]
    paced = bridge.get(PACED_HZ)
    if paced is None or paced.error:
        return [*lines, f"- At {PACED_HZ:g} Hz: not measured"]
    median = paced.median_us / 1000
    base = ceiling.get(PACED_HZ)
    beside = "" if base is None or base.error else f" (ceiling {base.median_us / 1000:.2f} ms)"
    lines.append(
        f"- Median latency at {PACED_HZ:g} Hz no worse than {GOAL_LATENCY_30HZ_MS:g} ms (issue "
        f"15's figure of this bridge): {median:.2f} ms{beside} — "
        f"{verdict(median <= GOAL_LATENCY_30HZ_MS, f'{median - GOAL_LATENCY_30HZ_MS:.2f} ms')}. "
        f"The C++ bridge: {LATENCY_30HZ.cpp_text()} ({QUOTED})."
    )
    frame = per_message_ms(paced.cpu, PACED_HZ, paced)
    if frame is not None:
        gap = f"{frame - GOAL_CPU_PER_FRAME_30HZ_MS:.2f} ms"
        lines.append(
            f"- Bridge CPU per frame at {PACED_HZ:g} Hz no worse than "
            f"{GOAL_CPU_PER_FRAME_30HZ_MS:g} ms: {frame:.2f} ms — "
            f"{verdict(frame <= GOAL_CPU_PER_FRAME_30HZ_MS, gap)}. The C++ bridge: "
            f"{CPU_PER_FRAME_30HZ.cpp_text()} ({QUOTED})."
        )
    return lines


def warm_up_text(hz: float, seconds: float, warm: FlowResult) -> str:
    """What the uncounted first flow through the fresh bridge showed."""
    if warm.error:
        return f"The uncounted first flow ({hz:g} Hz) failed: {warm.error}."
    return (
        f"Before the rates below, the fresh bridge carries one flow of {seconds:g} s at "
        f"{hz:g} Hz that is not counted, so that every row measures a bridge that has carried "
        f"frames. That first flow: {warm.received}/{warm.sent} frames, median "
        f"{warm.median_us / 1000:.2f} ms, p99 {warm.p99_us / 1000:.2f} ms (a fresh bridge's "
        "first conversions and writes of 6 MB samples to Fast DDS are slower than later ones: "
        "docs/environment.md, a fresh bridge's first frames)."
    )


def run(seconds: float, rates: list[float]) -> tuple[str, dict[str, FlowResult]]:
    cases = tuple((KIND, hz) for hz in rates)
    ceiling = ceilings(seconds, cases)
    warm, *rows = through_bridge(seconds, backend("zeromq"), ceiling, (cases[0], *cases), ())
    bridge = {row.hz: row.result for row in rows}
    base = {hz: ceiling[KIND, hz] for hz in rates}
    flows = {flow_key("bridge", hz): r for hz, r in bridge.items()}
    flows |= {flow_key("ceiling", hz): r for hz, r in base.items()}
    flows[flow_key(WARM_UP, warm.hz)] = warm.result
    table = "\n".join(_row(hz, bridge[hz], base[hz]) for hz in rates)
    flags = f" --seconds {seconds:g} --rates {' '.join(f'{hz:g}' for hz in rates)}"
    return (
        f"""## 1080p Gazebo -> ROS at rising rates: the highest sustainable rate (issue 15)

Command: `.venv/bin/python -m benchmarks.sustained{flags}`

A Gazebo publisher paced at each offered rate sends 1920x1080 rgb8 images for {seconds:g} s
through one parameter_bridge (ZeroMQ, its default QoS: reliable, keep-last 10) to an rclpy
subscriber; the ceiling is an rclpy publisher paced the same way to an rclpy subscriber, in
the same run, with the bridge's speed settings. A rate is **sustainable** when >=
{SUSTAINED_SHARE:.0%} of the frames arrive with a p99 latency under {SUSTAINED_P99_MS:g} ms;
the highest sustainable rate is the highest offered rate up to which every offered rate was.
Bridge CPU per frame = the bridge process's CPU time over the window / the frames delivered.
{warm_up_text(warm.hz, seconds, warm.result)}
{GZ_ENDS} Plot: [delivered rate and p99 latency against the offered rate]({link(SUSTAINED_PNG)}).

{HEADER}
{table}

Goals (issue 15):
{chr(10).join(goals(bridge, base))}
""",
        flows,
    )


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--seconds", type=float, default=5.0, help="publishing time per rate")
    parser.add_argument("--rates", type=float, nargs="+", default=list(RATES), help="Hz")
    args = parser.parse_args(argv)
    load = os.getloadavg()[0]
    section, flows = run(args.seconds, sorted(args.rates))
    write_section("sustained", section)
    store("sustained", flows, load)
    return 0


if __name__ == "__main__":
    sys.exit(main())

"""Markdown for flow results: one row per flow, set against its ceiling, and goal verdicts."""

from __future__ import annotations

from dataclasses import dataclass

from benchmarks.harness import FlowResult

HEADER = (
    "| path | message | publishing | msg/s | received/sent | median ms | p99 ms "
    "| bridge CPU | msg/s vs ceiling |\n|---|---|---|---|---|---|---|---|---|"
)
#: Bridge CPU share (% of one core) from which a flow counts as bound by the bridge itself.
CPU_BOUND = 85.0
SIZES = {
    "image640": "640x480 rgb8 Image",
    "image1080": "1920x1080 rgb8 Image",
    "cloud1mb": "1 MB PointCloud2",
    "twist": "Twist",
    "odometry": "Odometry",
    "tf20": "TFMessage (20)",
    "imu": "Imu",
    "clock": "Clock",
}


@dataclass(frozen=True)
class Row:
    path: str
    kind: str
    hz: float
    result: FlowResult
    ceiling: FlowResult | None = None

    @property
    def ratio(self) -> float | None:
        if self.ceiling is None or self.ceiling.rate <= 0:
            return None
        return self.result.rate / self.ceiling.rate


def _cpu(value: float | None) -> str:
    return "-" if value is None else f"{value:.0f}%"


def render(row: Row) -> str:
    r = row.result
    publishing = f"{row.hz:g} Hz" if row.hz else "flat out"
    if r.error:
        return f"| {row.path} | {SIZES[row.kind]} | {publishing} | failed: {r.error} |||||"
    if row.path.startswith("ceiling"):
        ratio = "ceiling"
    else:
        ratio = "-" if row.ratio is None else f"{row.ratio:.0%}"
    return (
        f"| {row.path} | {SIZES[row.kind]} | {publishing} | {r.rate:,.0f} "
        f"| {r.received}/{r.sent} | {r.median_us / 1000:.2f} | {r.p99_us / 1000:.2f} "
        f"| {_cpu(r.cpu)} | {ratio} |"
    )


def table(rows: list[Row]) -> str:
    return "\n".join([HEADER, *(render(row) for row in rows)])


def verdict(met: bool, miss: str) -> str:
    return "**met**" if met else f"**missed** by {miss}"


def rate_goal(row: Row, share: float) -> str:
    """``row`` reaches ``share`` of its ceiling's msg/s."""
    what = f"{row.path}, {SIZES[row.kind]}, {'flat out' if not row.hz else f'{row.hz:g} Hz'}"
    if row.ratio is None or row.result.error:
        return f"- {what} >= {share:.0%} of the ceiling: not measured"
    assert row.ceiling is not None
    met = row.ratio >= share
    gap = f"{(share - row.ratio) * 100:.0f} percentage points"
    return (
        f"- {what} >= {share:.0%} of the ceiling: {row.ratio:.0%} ({row.result.rate:,.0f} vs "
        f"{row.ceiling.rate:,.0f} msg/s) — {verdict(met, gap)}{'' if met else bound(row)}"
    )


def bound(row: Row) -> str:
    """What limited a flow that missed its goal, read from the bridge's CPU share."""
    cpu = row.result.cpu
    if cpu is None:
        return ""
    if cpu >= CPU_BOUND:
        return f"; bound by the bridge's CPU ({cpu:.0f}% of a core)"
    return (
        f"; the bridge was busy only {cpu:.0f}% of a core, so it waited on its ends: three busy "
        "processes (publisher, bridge, subscriber) share 2 cores where the ceiling has two"
    )


def latency_goal(row: Row, within_ms: float) -> str:
    """``row``'s median latency is at most ``within_ms`` above its ceiling's."""
    what = f"{row.path}, {SIZES[row.kind]} at {row.hz:g} Hz"
    if row.ceiling is None or row.result.error or row.ceiling.error:
        return f"- {what}: median within {within_ms:g} ms of the ceiling: not measured"
    added = (row.result.median_us - row.ceiling.median_us) / 1000
    return (
        f"- {what}: median within {within_ms:g} ms of the ceiling: {added:+.2f} ms "
        f"({row.result.median_us / 1000:.2f} vs {row.ceiling.median_us / 1000:.2f} ms) — "
        f"{verdict(added <= within_ms, f'{added - within_ms:.2f} ms')}"
        + ("" if added <= within_ms else HOP)
    )


#: Why a paced flow through the bridge is slower than the ceiling.
HOP = (
    "; the bridge path is one more hop: the Gazebo publisher's protobuf serialization, the "
    "ZeroMQ TCP transfer of the whole frame (a kernel copy each way), and the bulk path's "
    "serialized ROS message (written in the received frame, or one copy where it has no room); "
    "the DDS write and the subscriber are the ceiling's "
    '(see "transport" and "conversion" for those costs alone)'
)

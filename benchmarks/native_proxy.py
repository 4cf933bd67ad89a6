"""Is the bridge's CPU per message under a share of what an rclpy publisher and subscriber spend
on the same messages? Judged on the rows ``benchmarks.costs`` last stored (the proxy goal of
``benchmarks.native_plane``'s last section)."""

from __future__ import annotations

from benchmarks.costs import flow_key, per_message_ms
from benchmarks.results import load
from benchmarks.tables import SIZES, verdict

#: Issue 22's proxy for the C++ bridge: CPU per message at most this share of what an rclpy
#: publisher and an rclpy subscriber spend per message.
GOAL_PROXY = 0.4


#: The rows issue 22's proxy goal names: (direction, kind, rate).
PROXY_ROWS = (
    ("GZ->ROS", "odometry", 1000.0),
    ("GZ->ROS", "odometry", 5000.0),
    ("ROS->GZ", "twist", 1000.0),
    ("GZ->ROS", "tf20", 1000.0),
    ("GZ->ROS", "imu", 1000.0),
)


def proxy_lines() -> list[str]:
    """Issue 22's proxy goal judged on the rows ``benchmarks.costs`` last stored."""
    stored = load("costs")
    if stored is None:
        return ["- not measured yet (`benchmarks.costs`)"]
    lines = [f"From `benchmarks.costs` ({stored.run_line()}):"]
    for way, kind, hz in PROXY_ROWS:
        flow = stored.flow(flow_key(way, kind, hz))
        ceiling = stored.flow(flow_key("ceiling", kind, hz))
        if flow is None or ceiling is None:
            lines.append(f"- {SIZES[kind]} {way} at {hz / 1000:g} kHz: not measured")
            continue
        cost = per_message_ms(flow.cpu, hz, flow)
        ends = [per_message_ms(cpu, hz, ceiling) for cpu in (ceiling.pub_cpu, ceiling.sub_cpu)]
        if cost is None or ends[0] is None or ends[1] is None:
            continue
        bar = GOAL_PROXY * (ends[0] + ends[1])
        lines.append(
            f"- {SIZES[kind]} {way} at {hz / 1000:g} kHz: {cost:.3f} ms per message "
            f"({flow.received}/{flow.sent} delivered); bar {GOAL_PROXY:g} x ({ends[0]:.3f} + "
            f"{ends[1]:.3f}) = {bar:.3f} ms — "
            f"{verdict(cost <= bar, f'{cost - bar:.3f} ms ({cost / bar:.1f}x the bar)')}"
        )
    return lines

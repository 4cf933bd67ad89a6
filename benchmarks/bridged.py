"""Flows through a bridge process on either Gazebo Transport backend.

Zenoh runs on explicit loopback endpoints only: the bridge listens on ``tcp/127.0.0.1:PORT``
and the Gazebo workers connect to it, multicast scouting and gossip off.
"""

from __future__ import annotations

import sys
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass

from benchmarks.harness import (
    Flow,
    FlowFailure,
    FlowResult,
    bridge_argument,
    bridge_config,
    failed,
    run_flow,
    start_bridge,
    stop_all,
    topic_name,
)
from benchmarks.tables import Row
from testing.gzpeer import PeerProcess
from testing.loopback import free_port, zenoh_override
from testing.run_env import run_env


@dataclass(frozen=True)
class Backend:
    """The environments of a bridge process and of the Gazebo workers talking to it."""

    name: str
    bridge_env: dict[str, str]
    gz_env: dict[str, str]


def backend(name: str) -> Backend:
    if name == "zeromq":
        env = run_env()
        return Backend("ZeroMQ", env, env)
    endpoint = f"tcp/127.0.0.1:{free_port()}"
    bridge_env, gz_env = run_env("zenoh"), run_env("zenoh")
    bridge_env["GZ_TRANSPORT_ZENOH_CONFIG_OVERRIDE"] = zenoh_override(listen=[endpoint])
    gz_env["GZ_TRANSPORT_ZENOH_CONFIG_OVERRIDE"] = zenoh_override(connect=[endpoint])
    return Backend("Zenoh", bridge_env, gz_env)


@contextmanager
def bridge_process(
    arguments: list[str],
    env: dict[str, str],
    executable: str = "parameter_bridge",
    channels: int | None = None,
) -> Iterator[PeerProcess | None]:
    """A running bridge (None when it failed to start); stopped on exit."""
    bridge: PeerProcess | None = None
    try:
        bridge = start_bridge(arguments, env, executable, channels)
    except FlowFailure as error:
        print(f"{executable} did not start: {failed(error).error}", file=sys.stderr)
    try:
        yield bridge
    finally:
        stop_all()


def flow_through(
    flow: Flow,
    topic: str,
    which: Backend,
    bridge: PeerProcess | None,
    during: Callable[[], None] | None = None,
) -> FlowResult:
    """``flow`` through a running ``bridge`` of backend ``which`` on ``topic``."""
    if bridge is None:
        return FlowResult(0, 0, 0.0, 0.0, 0.0, None, "bridge did not start")
    ros_env = run_env()
    pub_env, sub_env = (
        (which.gz_env, ros_env) if flow.publisher == "gz-pub" else (ros_env, which.gz_env)
    )
    result = run_flow(flow, topic, sub_env, pub_env=pub_env, bridge_pid=bridge.pid, during=during)
    print(f"{which.name} {flow}: {result}", file=sys.stderr, flush=True)
    if result.error:
        print(f"bridge output:\n{bridge.output()[-3000:]}", file=sys.stderr, flush=True)
    return result


#: (message kind, publishing rate) pairs; rate 0 = flat out.
Cases = tuple[tuple[str, float], ...]
Ceilings = dict[tuple[str, float], FlowResult]


def unbridged(
    seconds: float, cases: Cases, ends: tuple[str, str], label: str, depth: int | None = None
) -> Ceilings:
    """Publisher -> subscriber (``ends``, worker roles) of each case with no bridge between
    (``depth``: the history depth of the ROS ends, None: their default)."""
    env = run_env()
    results = {}
    for kind, hz in cases:
        topic = topic_name(f"{label.replace(' ', '_')}_{kind}")
        results[kind, hz] = run_flow(Flow(*ends, kind, seconds, hz, depth=depth), topic, env)
        print(f"{label} {kind} {hz:g}: {results[kind, hz]}", file=sys.stderr, flush=True)
    return results


def ceilings(seconds: float, cases: Cases, depth: int | None = None) -> Ceilings:
    """rclpy publisher -> rclpy subscriber of each case, no bridge, the bridge's settings."""
    return unbridged(seconds, cases, ("ros-pub", "ros-sub"), "ceiling", depth)


def through_bridge(
    seconds: float,
    which: Backend,
    ceiling: Ceilings,
    gz_cases: Cases,
    ros_cases: Cases,
    *,
    depth: int | None = None,
) -> list[Row]:
    """GZ->ROS and ROS->GZ flows through one parameter_bridge with a channel per kind and way.

    ``depth``: the history depth of the ROS ends and of the bridge's channels (its YAML
    ``publisher_queue`` and ``subscriber_queue``); None keeps everyone's default, 10.
    """
    gz2ros = {kind: topic_name(f"g2r_{kind}") for kind, _ in gz_cases}
    ros2gz = {kind: topic_name(f"r2g_{kind}") for kind, _ in ros_cases}
    channels = [(t, k, "gz2ros") for k, t in gz2ros.items()]
    channels += [(t, k, "ros2gz") for k, t in ros2gz.items()]
    if depth is None:
        arguments = [bridge_argument(*channel) for channel in channels]
    else:
        arguments = bridge_config(channels, depth)
    rows = []
    with bridge_process(arguments, which.bridge_env, channels=len(channels)) as bridge:
        for way, cases, topics in (("GZ->ROS", gz_cases, gz2ros), ("ROS->GZ", ros_cases, ros2gz)):
            ends = ("gz-pub", "ros-sub") if way == "GZ->ROS" else ("ros-pub", "gz-sub")
            for kind, hz in cases:
                flow = Flow(*ends, kind, seconds, hz, depth=depth)
                result = flow_through(flow, topics[kind], which, bridge)
                path = f"{way} parameter_bridge ({which.name})"
                if depth is not None:
                    path += f", queues {depth}"
                rows.append(Row(path, kind, hz, result, ceiling.get((kind, hz))))
    return rows

"""The ROS endpoints at a channel's far end, as the explanations judge them: their types, and
whether their QoS can match the bridge's, with the ``qos_overrides`` that would make it.

Shared by the running bridge (``explain.py``) and ``parameter_bridge --check``.
"""

from __future__ import annotations

import copy
from collections.abc import Iterable
from typing import Any

from rclpy.duration import Infinite
from rclpy.qos import (
    DurabilityPolicy,
    LivelinessPolicy,
    QoSCompatibility,
    QoSProfile,
    ReliabilityPolicy,
    qos_check_compatible,
)

from ros_gz_bridge_py.config import Direction
from ros_gz_bridge_py.core.diagnosis import RosEndpoint


def ros_endpoints(
    ros_node: Any,
    direction: Direction,
    ros_topic: str,
    our_qos: QoSProfile,
    own_nodes: Iterable[tuple[str, str]],
) -> list[RosEndpoint]:
    """The ROS endpoints at the far end of a channel: the subscribers a Gazebo->ROS channel
    publishes to, or the publishers a ROS->Gazebo channel reads; the bridge's own left out.
    ``our_qos``: the channel's profile as the graph shows it (:func:`as_the_graph_shows`)."""
    own = set(own_nodes)
    to_ros = direction is Direction.GZ_TO_ROS
    infos = (
        ros_node.get_subscriptions_info_by_topic(ros_topic)
        if to_ros
        else ros_node.get_publishers_info_by_topic(ros_topic)
    )
    found = []
    for info in infos:
        if (info.node_name, info.node_namespace) in own:
            continue
        namespace = info.node_namespace.rstrip("/")
        node = f"{namespace}/{info.node_name}"
        publisher, subscription = (
            (our_qos, info.qos_profile) if to_ros else (info.qos_profile, our_qos)
        )
        compatibility, reason = qos_check_compatible(publisher, subscription)
        problem = ""
        fixes: tuple[str, ...] = ()
        if compatibility == QoSCompatibility.ERROR:
            problem = qos_errors(reason)
            fixes = qos_fixes(to_ros, publisher, subscription)
        found.append(
            RosEndpoint(node, info.topic_type, problem, describe_qos(info.qos_profile), fixes)
        )
    return found


def qos_errors(reason: str) -> str:
    """rcl's ``"ERROR: a;WARNING: b;ERROR: c;"`` as ``"a, c"``: the incompatibilities only,
    without rcl's markup, for a sentence of ours."""
    errors = [part.strip() for part in reason.split(";") if part.strip().startswith("ERROR:")]
    return ", ".join(error.removeprefix("ERROR:").strip() for error in errors) or reason.strip()


def qos_fixes(we_publish: bool, publisher: QoSProfile, subscription: QoSProfile) -> tuple[str, ...]:
    """The ``qos_overrides`` of the bridge's endpoint (``publisher.durability:=transient_local``)
    that match the other end's reliability and durability, the incompatibilities users meet
    (a transient-local /map reader; a best-effort sensor publisher). Empty when those match:
    then another policy (deadline, liveliness) is at fault, which the entry's profile sets."""
    ours, theirs = (publisher, subscription) if we_publish else (subscription, publisher)
    side = "publisher" if we_publish else "subscription"
    fixes = []
    if (publisher.reliability, subscription.reliability) == (
        ReliabilityPolicy.BEST_EFFORT,
        ReliabilityPolicy.RELIABLE,
    ):
        fixes.append(f"{side}.reliability:={theirs.reliability.name.lower()}")
    if we_publish and (ours.durability, theirs.durability) == (
        DurabilityPolicy.VOLATILE,
        DurabilityPolicy.TRANSIENT_LOCAL,
    ):  # a subscription's durability has no override (rclpy's default policies)
        fixes.append("publisher.durability:=transient_local")
    return tuple(fixes)


def as_the_graph_shows(profile: QoSProfile) -> QoSProfile:
    """``profile`` with its "default" durations and liveliness as the graph reports them for
    a live endpoint (infinite, automatic); compared as they are, a default deadline reads as
    "none" against an infinite one and every pair looks incompatible."""
    shown = copy.copy(profile)
    for name in ("deadline", "lifespan", "liveliness_lease_duration"):
        if getattr(shown, name).nanoseconds == 0:
            setattr(shown, name, Infinite)
    if shown.liveliness == LivelinessPolicy.SYSTEM_DEFAULT:
        shown.liveliness = LivelinessPolicy.AUTOMATIC
    return shown


def describe_qos(profile: QoSProfile) -> str:
    """``reliable, volatile, depth 10`` (keep-all histories say so)."""
    history = f"depth {profile.depth}" if profile.history.name == "KEEP_LAST" else "keep all"
    return f"{profile.reliability.name.lower()}, {profile.durability.name.lower()}, {history}"

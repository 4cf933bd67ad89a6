"""ROS QoS for bridge endpoints: the C++ defaults, the named profiles and per-topic overrides.

Defaults follow ros_gz_bridge: reliable, volatile, keep-last 10 on both ROS endpoints. One
deliberate difference: a Gazebo->ROS publisher on ``/tf_static`` is transient-local by default,
so late-joining TF listeners get the static transforms (ros_gz issues #250, ardupilot_gz#36).
Users still override everything with ``qos_overrides.<topic>.publisher|subscription.<policy>``,
which rclpy reads from the node's parameters when the endpoint is created.
"""

from __future__ import annotations

import warnings
from typing import Any

from rcl_interfaces.msg import SetParametersResult
from rclpy.duration import Duration
from rclpy.publisher import Publisher
from rclpy.qos import (
    DurabilityPolicy,
    HistoryPolicy,
    QoSProfile,
    ReliabilityPolicy,
    qos_profile_best_available,
    qos_profile_parameter_events,
    qos_profile_parameters,
    qos_profile_sensor_data,
    qos_profile_services_default,
    qos_profile_system_default,
)
from rclpy.qos_overriding_options import (  # the function create_subscription calls
    QoSOverridingOptions,
    QoSPolicyKind,
    _declare_qos_parameters,
)
from rclpy.subscription import Subscription

from ros_gz_bridge_py.errors import ConfigError

DEFAULT_DEPTH = 10
TF_STATIC_TOPIC = "/tf_static"


def _keep_last(
    depth: int,
    reliability: ReliabilityPolicy,
    durability: DurabilityPolicy,
    lifespan: Duration | None = None,
) -> QoSProfile:
    profile = QoSProfile(
        history=HistoryPolicy.KEEP_LAST, depth=depth, reliability=reliability, durability=durability
    )
    if lifespan is not None:
        profile.lifespan = lifespan
    return profile


#: ``qos_profile`` names (as the C++ bridge spells them) -> a function returning a fresh profile.
NAMED_PROFILES: dict[str, Any] = {
    # rclcpp::ClockQoS
    "CLOCK": lambda: _keep_last(1, ReliabilityPolicy.BEST_EFFORT, DurabilityPolicy.VOLATILE),
    "SENSOR_DATA": lambda: QoSProfile(**_fields(qos_profile_sensor_data)),
    "PARAMETERS": lambda: QoSProfile(**_fields(qos_profile_parameters)),
    "SERVICES": lambda: QoSProfile(**_fields(qos_profile_services_default)),
    "PARAMETER_EVENTS": lambda: QoSProfile(**_fields(qos_profile_parameter_events)),
    # rclcpp::RosoutQoS
    "ROSOUT": lambda: _keep_last(
        1000, ReliabilityPolicy.RELIABLE, DurabilityPolicy.TRANSIENT_LOCAL, Duration(seconds=10)
    ),
    "SYSTEM_DEFAULT": lambda: QoSProfile(**_fields(qos_profile_system_default)),
    "BEST_AVAILABLE": lambda: QoSProfile(**_fields(qos_profile_best_available)),
}


def _depth_checked(qos: QoSProfile) -> SetParametersResult:
    """rclpy's check of the overridden profile: a negative depth reached the middleware,
    whose error ("the requested queue size exceeds the DDS type") came with an rcutils
    'error state is being overwritten' block on stderr."""
    if qos.depth < 0:
        reason = (
            f"depth {qos.depth} is negative; give the depth of history to keep (0: the "
            "middleware's default)"
        )
        return SetParametersResult(successful=False, reason=reason)
    return SetParametersResult(successful=True)


#: Policies users may override per publisher (rclcpp Jazzy set) and per subscription.
PUBLISHER_OVERRIDES = QoSOverridingOptions(
    policy_kinds=(
        QoSPolicyKind.DEADLINE,
        QoSPolicyKind.DEPTH,
        QoSPolicyKind.DURABILITY,
        QoSPolicyKind.HISTORY,
        QoSPolicyKind.LIVELINESS,
        QoSPolicyKind.RELIABILITY,
    ),
    callback=_depth_checked,
)
SUBSCRIPTION_OVERRIDES = QoSOverridingOptions.with_default_policies(callback=_depth_checked)


def apply_subscription_overrides(node: Any, topic: str, qos: QoSProfile) -> None:
    """Apply to ``qos`` (in place) the ``qos_overrides`` of a subscription of ``topic`` on
    ``node``, declaring its parameters there, as ``create_subscription`` does.

    For a subscription the bridge creates on its side node: the user wrote the overrides for
    the bridge node (``-p`` for its name, a params file, ``parameter_overrides``), so they are
    read and shown there. rclpy's own function is used, so the names, the policies and the
    errors are rclpy's.
    """
    _declare_qos_parameters(
        Subscription, node, node.resolve_topic_name(topic), qos, SUBSCRIPTION_OVERRIDES
    )


def apply_publisher_overrides(node: Any, topic: str, qos: QoSProfile) -> None:
    """Apply to ``qos`` (in place) the ``qos_overrides`` of a publisher of ``topic`` on
    ``node``, as ``create_publisher`` with :data:`PUBLISHER_OVERRIDES` does: for what
    ``--check`` compares with the ROS endpoints it sees."""
    _declare_qos_parameters(
        Publisher, node, node.resolve_topic_name(topic), qos, PUBLISHER_OVERRIDES
    )


def _fields(profile: QoSProfile) -> dict[str, Any]:
    return {
        "history": profile.history,
        "depth": profile.depth,
        "reliability": profile.reliability,
        "durability": profile.durability,
        "lifespan": profile.lifespan,
        "deadline": profile.deadline,
        "liveliness": profile.liveliness,
        "liveliness_lease_duration": profile.liveliness_lease_duration,
    }


def endpoint_qos(profile_name: str | None, depth: int | None) -> QoSProfile:
    """The QoS for one ROS endpoint of a bridge.

    ``depth`` is the entry's ``publisher_queue``/``subscriber_queue`` (None: unset). Without a
    profile it is the C++ default (reliable, volatile, keep-last ``depth`` or 10); with one, the
    profile, its depth replaced by ``depth`` when that is set.

    Raises:
        ConfigError: ``profile_name`` is not one of :data:`NAMED_PROFILES`.
    """
    if depth == 0:
        # The config parser warns about a queue of 0 naming the entry and line; rclpy's own
        # warning (here, and again when the endpoint applies its qos_overrides) names neither.
        warnings.filterwarnings(
            "ignore", "A zero depth with KEEP_LAST", UserWarning, module="rclpy.qos"
        )
    if profile_name is None:
        return QoSProfile(
            history=HistoryPolicy.KEEP_LAST,
            depth=DEFAULT_DEPTH if depth is None else depth,
            reliability=ReliabilityPolicy.RELIABLE,
            durability=DurabilityPolicy.VOLATILE,
        )
    make = NAMED_PROFILES.get(profile_name)
    if make is None:
        known = ", ".join(sorted(NAMED_PROFILES))
        msg = f"unknown QoS profile [{profile_name}]; use one of {known}"
        raise ConfigError(msg)
    profile: QoSProfile = make()
    if depth is not None:
        profile.history = HistoryPolicy.KEEP_LAST
        profile.depth = depth
    return profile


def gz_to_ros_publisher_qos(
    resolved_topic: str, profile_name: str | None, depth: int | None
) -> QoSProfile:
    """Publisher QoS of a Gazebo->ROS channel, with ``/tf_static`` latched by default."""
    profile = endpoint_qos(profile_name, depth)
    if profile_name is None and resolved_topic == TF_STATIC_TOPIC:
        profile.durability = DurabilityPolicy.TRANSIENT_LOCAL
    return profile

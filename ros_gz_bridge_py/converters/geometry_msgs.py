"""geometry_msgs pairs (conversions.md §1.4, §1.5, §3.3) and the fill helpers they share.

``fill_gz_*(ros, gz)`` and ``fill_ros_*(gz, ros)`` write a source message into an existing
target (source first, as in the C++ ``convert_*`` functions), so composite converters in other
modules build on them. Values are copied verbatim: quaternions are not normalised, and a gz
orientation without ``w`` reads as (0, 0, 0, 0), as in the reference.
"""

from __future__ import annotations

from collections.abc import Iterable
from typing import Any

from geometry_msgs.msg import (
    Point,
    Pose,
    PoseArray,
    PoseStamped,
    PoseWithCovariance,
    PoseWithCovarianceStamped,
    Quaternion,
    Transform,
    TransformStamped,
    Twist,
    TwistStamped,
    TwistWithCovariance,
    TwistWithCovarianceStamped,
    Vector3,
    Wrench,
    WrenchStamped,
)

from ros_gz_bridge_py.converters.registry import Pair
from ros_gz_bridge_py.converters.std_msgs import (
    fill_gz_child_frame_id,
    fill_gz_header,
    fill_ros_header,
    ros_child_frame_id,
)
from ros_gz_bridge_py.msgs import message_class

GzVector3d = message_class("gz.msgs.Vector3d")
GzQuaternion = message_class("gz.msgs.Quaternion")
GzPose = message_class("gz.msgs.Pose")
GzPoseV = message_class("gz.msgs.Pose_V")
GzPoseWithCovariance = message_class("gz.msgs.PoseWithCovariance")
GzTwist = message_class("gz.msgs.Twist")
GzTwistWithCovariance = message_class("gz.msgs.TwistWithCovariance")
GzWrench = message_class("gz.msgs.Wrench")

#: Row-major 6x6 over (x, y, z, rot X, rot Y, rot Z).
POSE_COVARIANCE_SIZE = 36


def fill_gz_vector3(ros: Any, gz: Any) -> None:
    """ROS Vector3 or Point -> gz Vector3d (marks the submessage present)."""
    gz.x = ros.x
    gz.y = ros.y
    gz.z = ros.z


def fill_ros_vector3(gz: Any, ros: Any) -> None:
    """gz Vector3d -> ROS Vector3 or Point."""
    ros.x = gz.x
    ros.y = gz.y
    ros.z = gz.z


def fill_gz_quaternion(ros: Any, gz: Any) -> None:
    gz.x = ros.x
    gz.y = ros.y
    gz.z = ros.z
    gz.w = ros.w


def fill_ros_quaternion(gz: Any, ros: Any) -> None:
    ros.x = gz.x
    ros.y = gz.y
    ros.z = gz.z
    ros.w = gz.w


def fill_gz_covariance(values: Iterable[float], gz_float_v: Any) -> None:
    """Append every ROS covariance value to a gz Float_V (float64 -> float32, lossy)."""
    gz_float_v.SetInParent()
    gz_float_v.data.extend(values)


def covariance_to_ros(gz_float_v: Any, size: int) -> list[float]:
    """The gz Float_V values when there are exactly ``size`` of them, else ``size`` zeros."""
    data = gz_float_v.data
    return list(data) if len(data) == size else [0.0] * size


def fill_gz_pose(ros: Any, gz: Any) -> None:
    """ROS Pose -> gz Pose position/orientation; gz header, name, id stay unset."""
    fill_gz_vector3(ros.position, gz.position)
    fill_gz_quaternion(ros.orientation, gz.orientation)


def fill_ros_pose(gz: Any, ros: Any) -> None:
    fill_ros_vector3(gz.position, ros.position)
    fill_ros_quaternion(gz.orientation, ros.orientation)


def fill_gz_transform(ros: Any, gz: Any) -> None:
    """ROS Transform -> gz Pose (translation -> position, rotation -> orientation)."""
    fill_gz_vector3(ros.translation, gz.position)
    fill_gz_quaternion(ros.rotation, gz.orientation)


def fill_ros_transform(gz: Any, ros: Any) -> None:
    fill_ros_vector3(gz.position, ros.translation)
    fill_ros_quaternion(gz.orientation, ros.rotation)


def fill_gz_transform_stamped(ros: Any, gz: Any) -> None:
    """Header with ``frame_id`` then ``child_frame_id`` entries, plus the transform."""
    fill_gz_header(ros.header, gz.header)
    fill_gz_child_frame_id(ros.child_frame_id, gz.header)
    fill_gz_transform(ros.transform, gz)


def fill_ros_transform_stamped(gz: Any, ros: Any) -> None:
    fill_ros_header(gz.header, ros.header)
    ros.child_frame_id = ros_child_frame_id(gz.header)
    fill_ros_transform(gz, ros.transform)


def fill_gz_twist(ros: Any, gz: Any) -> None:
    fill_gz_vector3(ros.linear, gz.linear)
    fill_gz_vector3(ros.angular, gz.angular)


def fill_ros_twist(gz: Any, ros: Any) -> None:
    fill_ros_vector3(gz.linear, ros.linear)
    fill_ros_vector3(gz.angular, ros.angular)


def fill_gz_wrench(ros: Any, gz: Any) -> None:
    """force and torque; gz ``force_offset`` is never written."""
    fill_gz_vector3(ros.force, gz.force)
    fill_gz_vector3(ros.torque, gz.torque)


def fill_ros_wrench(gz: Any, ros: Any) -> None:
    fill_ros_vector3(gz.force, ros.force)
    fill_ros_vector3(gz.torque, ros.torque)


def fill_gz_pose_with_covariance(ros: Any, gz: Any) -> None:
    fill_gz_pose(ros.pose, gz.pose)
    fill_gz_covariance(ros.covariance, gz.covariance)


def fill_ros_pose_with_covariance(gz: Any, ros: Any) -> None:
    fill_ros_pose(gz.pose, ros.pose)
    ros.covariance = covariance_to_ros(gz.covariance, POSE_COVARIANCE_SIZE)


def fill_gz_twist_with_covariance(ros: Any, gz: Any) -> None:
    fill_gz_twist(ros.twist, gz.twist)
    fill_gz_covariance(ros.covariance, gz.covariance)


def fill_ros_twist_with_covariance(gz: Any, ros: Any) -> None:
    fill_ros_twist(gz.twist, ros.twist)
    ros.covariance = covariance_to_ros(gz.covariance, POSE_COVARIANCE_SIZE)


# --- whole-message converters, one pair each ---------------------------------------------


def _pose_stamped_to_gz(ros: Any) -> Any:
    gz = GzPose()
    fill_gz_header(ros.header, gz.header)
    fill_gz_pose(ros.pose, gz)
    return gz


def _pose_stamped_to_ros(gz: Any) -> Any:
    ros = PoseStamped()
    fill_ros_header(gz.header, ros.header)
    fill_ros_pose(gz, ros.pose)
    return ros


def _pose_array_to_gz(ros: Any) -> Any:
    gz = GzPoseV()
    fill_gz_header(ros.header, gz.header)
    for pose in ros.poses:
        fill_gz_pose(pose, gz.pose.add())
    return gz


def _pose_array_to_ros(gz: Any) -> Any:
    ros = PoseArray()
    fill_ros_header(gz.header, ros.header)
    poses = []
    for gz_pose in gz.pose:
        pose = Pose()
        fill_ros_pose(gz_pose, pose)
        poses.append(pose)
    ros.poses = poses
    return ros


def _pose_with_covariance_stamped_to_gz(ros: Any) -> Any:
    gz = GzPoseWithCovariance()
    fill_gz_header(ros.header, gz.pose.header)
    fill_gz_pose_with_covariance(ros.pose, gz)
    return gz


def _pose_with_covariance_stamped_to_ros(gz: Any) -> Any:
    ros = PoseWithCovarianceStamped()
    fill_ros_header(gz.pose.header, ros.header)
    fill_ros_pose_with_covariance(gz, ros.pose)
    return ros


def _twist_stamped_to_gz(ros: Any) -> Any:
    gz = GzTwist()
    fill_gz_header(ros.header, gz.header)
    fill_gz_twist(ros.twist, gz)
    return gz


def _twist_stamped_to_ros(gz: Any) -> Any:
    ros = TwistStamped()
    fill_ros_header(gz.header, ros.header)
    fill_ros_twist(gz, ros.twist)
    return ros


def _twist_with_covariance_stamped_to_gz(ros: Any) -> Any:
    gz = GzTwistWithCovariance()
    fill_gz_header(ros.header, gz.twist.header)
    fill_gz_twist_with_covariance(ros.twist, gz)
    return gz


def _twist_with_covariance_stamped_to_ros(gz: Any) -> Any:
    ros = TwistWithCovarianceStamped()
    fill_ros_header(gz.twist.header, ros.header)
    fill_ros_twist_with_covariance(gz, ros.twist)
    return ros


def _wrench_stamped_to_gz(ros: Any) -> Any:
    gz = GzWrench()
    fill_gz_header(ros.header, gz.header)
    fill_gz_wrench(ros.wrench, gz)
    return gz


def _wrench_stamped_to_ros(gz: Any) -> Any:
    ros = WrenchStamped()
    fill_ros_header(gz.header, ros.header)
    fill_ros_wrench(gz, ros.wrench)
    return ros


def _fill_pair(
    ros_class: type[Any],
    gz_name: str,
    fill_gz: Any,
    fill_ros: Any,
) -> Pair:
    """A pair whose two directions are one fill helper each into a fresh target."""
    gz_class = message_class(gz_name)

    def to_gz(ros: Any) -> Any:
        gz = gz_class()
        fill_gz(ros, gz)
        return gz

    def to_ros(gz: Any) -> Any:
        ros = ros_class()
        fill_ros(gz, ros)
        return ros

    return Pair(f"geometry_msgs/msg/{ros_class.__name__}", gz_name, to_gz, to_ros, ros_class)


def _pair(
    ros_class: type[Any],
    gz_name: str,
    to_gz: Any,
    to_ros: Any,
    *,
    default_for_gz_type: bool = False,
) -> Pair:
    name = f"geometry_msgs/msg/{ros_class.__name__}"
    return Pair(name, gz_name, to_gz, to_ros, ros_class, default_for_gz_type=default_for_gz_type)


PAIRS = (
    _fill_pair(Point, "gz.msgs.Vector3d", fill_gz_vector3, fill_ros_vector3),
    _fill_pair(Pose, "gz.msgs.Pose", fill_gz_pose, fill_ros_pose),
    # tf2_msgs/msg/TFMessage pairs with gz.msgs.Pose_V too.
    _pair(
        PoseArray,
        "gz.msgs.Pose_V",
        _pose_array_to_gz,
        _pose_array_to_ros,
        default_for_gz_type=True,
    ),
    _pair(PoseStamped, "gz.msgs.Pose", _pose_stamped_to_gz, _pose_stamped_to_ros),
    _fill_pair(
        PoseWithCovariance,
        "gz.msgs.PoseWithCovariance",
        fill_gz_pose_with_covariance,
        fill_ros_pose_with_covariance,
    ),
    _pair(
        PoseWithCovarianceStamped,
        "gz.msgs.PoseWithCovariance",
        _pose_with_covariance_stamped_to_gz,
        _pose_with_covariance_stamped_to_ros,
    ),
    _fill_pair(Quaternion, "gz.msgs.Quaternion", fill_gz_quaternion, fill_ros_quaternion),
    _fill_pair(Transform, "gz.msgs.Pose", fill_gz_transform, fill_ros_transform),
    _fill_pair(
        TransformStamped, "gz.msgs.Pose", fill_gz_transform_stamped, fill_ros_transform_stamped
    ),
    _fill_pair(Twist, "gz.msgs.Twist", fill_gz_twist, fill_ros_twist),
    _pair(TwistStamped, "gz.msgs.Twist", _twist_stamped_to_gz, _twist_stamped_to_ros),
    _fill_pair(
        TwistWithCovariance,
        "gz.msgs.TwistWithCovariance",
        fill_gz_twist_with_covariance,
        fill_ros_twist_with_covariance,
    ),
    _pair(
        TwistWithCovarianceStamped,
        "gz.msgs.TwistWithCovariance",
        _twist_with_covariance_stamped_to_gz,
        _twist_with_covariance_stamped_to_ros,
    ),
    _fill_pair(Vector3, "gz.msgs.Vector3d", fill_gz_vector3, fill_ros_vector3),
    _fill_pair(Wrench, "gz.msgs.Wrench", fill_gz_wrench, fill_ros_wrench),
    _pair(WrenchStamped, "gz.msgs.Wrench", _wrench_stamped_to_gz, _wrench_stamped_to_ros),
)

"""tf2_msgs/msg/TFMessage <-> gz.msgs.Pose_V (conversions.md §3.7).

Each transform is one gz Pose carrying its own header (``frame_id`` and ``child_frame_id``).
R→G also writes the first transform's header (stamp and ``frame_id``) as the Pose_V header;
G→R ignores the Pose_V header and reads every pose's own.
"""

from __future__ import annotations

from typing import Any

from geometry_msgs.msg import TransformStamped
from tf2_msgs.msg import TFMessage

from ros_gz_bridge_py.converters.geometry_msgs import TRANSFORM_STAMPED
from ros_gz_bridge_py.converters.registry import Pair
from ros_gz_bridge_py.converters.std_msgs import HEADER
from ros_gz_bridge_py.msgs import message_class

GzPoseV = message_class("gz.msgs.Pose_V")


def tf_message_to_gz(ros: Any) -> Any:
    gz = GzPoseV()
    transforms = ros.transforms
    if transforms:
        HEADER.to_gz(transforms[0].header, gz.header)
    for transform in transforms:
        TRANSFORM_STAMPED.to_gz(transform, gz.pose.add())
    return gz


def tf_message_to_ros(gz: Any) -> Any:
    transforms = []
    for pose in gz.pose:
        transform = TransformStamped()
        TRANSFORM_STAMPED.to_ros(pose, transform)
        transforms.append(transform)
    return TFMessage(transforms=transforms)


PAIRS = (Pair.of(TFMessage, "gz.msgs.Pose_V", tf_message_to_gz, tf_message_to_ros),)

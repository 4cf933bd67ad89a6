"""tf2_msgs/msg/TFMessage <-> gz.msgs.Pose_V (docs/conversions-per-package.md §3.7).

Each transform is one gz Pose carrying its own header (``frame_id`` and ``child_frame_id``).
R→G also writes the first transform's header (stamp and ``frame_id``) as the Pose_V header;
G→R ignores the Pose_V header and reads every pose's own.
"""

from __future__ import annotations

from typing import Any

from geometry_msgs.msg import TransformStamped
from tf2_msgs.msg import TFMessage

from ros_gz_bridge_py.converters._fields import converters, each, fields
from ros_gz_bridge_py.converters.geometry_msgs import TRANSFORM_STAMPED
from ros_gz_bridge_py.converters.registry import Pair
from ros_gz_bridge_py.converters.std_msgs import HEADER

_TRANSFORMS = fields(("transforms", "pose", each(TRANSFORM_STAMPED, TransformStamped)))
_transforms_to_gz, tf_message_to_ros = converters(_TRANSFORMS, TFMessage, "gz.msgs.Pose_V")


def tf_message_to_gz(ros: Any) -> Any:
    gz = _transforms_to_gz(ros)
    if ros.transforms:
        HEADER.to_gz(ros.transforms[0].header, gz.header)
    return gz


PAIRS = (Pair.of(TFMessage, "gz.msgs.Pose_V", tf_message_to_gz, tf_message_to_ros),)

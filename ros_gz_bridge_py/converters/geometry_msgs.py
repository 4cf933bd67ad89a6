"""geometry_msgs pairs (docs/conversions.md §1.4, §1.5; docs/conversions-per-package.md §3.3)
and the fill helpers they share.

The :class:`~ros_gz_bridge_py.converters._fields.Fill` constants (``VECTOR3``, ``POSE``,
``TWIST``, ...) write a source message into an existing target, both ways, so composite
converters in other modules build on them. Values are copied verbatim: quaternions are not
normalised, and a gz orientation without ``w`` reads as (0, 0, 0, 0), as in the reference.
"""

from __future__ import annotations

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

from ros_gz_bridge_py.converters._fields import WHOLE, each, fields, fill_pair
from ros_gz_bridge_py.converters.covariance import COVARIANCE
from ros_gz_bridge_py.converters.std_msgs import FRAMES, HEADER

#: ROS Vector3 or Point <-> gz Vector3d (writing a field marks the gz submessage present).
VECTOR3 = fields("x", "y", "z")
QUATERNION = fields("x", "y", "z", "w")

#: ROS Pose -> gz Pose position/orientation; gz header, name, id stay unset.
POSE = fields(("position", VECTOR3), ("orientation", QUATERNION))
#: ROS Transform -> gz Pose (translation -> position, rotation -> orientation).
TRANSFORM = fields(("translation", "position", VECTOR3), ("rotation", "orientation", QUATERNION))
#: Header with ``frame_id`` then ``child_frame_id`` entries, plus the transform.
TRANSFORM_STAMPED = fields(FRAMES, ("transform", WHOLE, TRANSFORM))
TWIST = fields(("linear", VECTOR3), ("angular", VECTOR3))
#: force and torque; gz ``force_offset`` is never written.
WRENCH = fields(("force", VECTOR3), ("torque", VECTOR3))
POSE_WITH_COVARIANCE = fields(("pose", POSE), ("covariance", COVARIANCE))
TWIST_WITH_COVARIANCE = fields(("twist", TWIST), ("covariance", COVARIANCE))


PAIRS = (
    fill_pair(Point, "gz.msgs.Vector3d", VECTOR3),
    fill_pair(Pose, "gz.msgs.Pose", POSE),
    # tf2_msgs/msg/TFMessage pairs with gz.msgs.Pose_V too.
    fill_pair(
        PoseArray,
        "gz.msgs.Pose_V",
        fields(("header", HEADER), ("poses", "pose", each(POSE, Pose))),
        default_for_gz_type=True,
    ),
    fill_pair(PoseStamped, "gz.msgs.Pose", fields(("header", HEADER), ("pose", WHOLE, POSE))),
    fill_pair(PoseWithCovariance, "gz.msgs.PoseWithCovariance", POSE_WITH_COVARIANCE),
    fill_pair(
        PoseWithCovarianceStamped,
        "gz.msgs.PoseWithCovariance",
        fields(("header", "pose.header", HEADER), ("pose", WHOLE, POSE_WITH_COVARIANCE)),
    ),
    fill_pair(Quaternion, "gz.msgs.Quaternion", QUATERNION),
    fill_pair(Transform, "gz.msgs.Pose", TRANSFORM),
    fill_pair(TransformStamped, "gz.msgs.Pose", TRANSFORM_STAMPED),
    fill_pair(Twist, "gz.msgs.Twist", TWIST),
    fill_pair(TwistStamped, "gz.msgs.Twist", fields(("header", HEADER), ("twist", WHOLE, TWIST))),
    fill_pair(TwistWithCovariance, "gz.msgs.TwistWithCovariance", TWIST_WITH_COVARIANCE),
    fill_pair(
        TwistWithCovarianceStamped,
        "gz.msgs.TwistWithCovariance",
        fields(("header", "twist.header", HEADER), ("twist", WHOLE, TWIST_WITH_COVARIANCE)),
    ),
    fill_pair(Vector3, "gz.msgs.Vector3d", VECTOR3),
    fill_pair(Wrench, "gz.msgs.Wrench", WRENCH),
    fill_pair(
        WrenchStamped, "gz.msgs.Wrench", fields(("header", HEADER), ("wrench", WHOLE, WRENCH))
    ),
)

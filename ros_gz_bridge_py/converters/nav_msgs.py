"""nav_msgs/msg/Odometry <-> gz.msgs.Odometry (default) and gz.msgs.OdometryWithCovariance
(docs/conversions-per-package.md §3.4).

With gz.msgs.Odometry both ROS covariances are dropped (R→G) and left zero (G→R).
"""

from __future__ import annotations

from nav_msgs.msg import Odometry

from ros_gz_bridge_py.converters._fields import fields, fill_pair
from ros_gz_bridge_py.converters.geometry_msgs import (
    POSE,
    POSE_WITH_COVARIANCE,
    TWIST,
    TWIST_WITH_COVARIANCE,
)
from ros_gz_bridge_py.converters.std_msgs import FRAMES

PAIRS = (
    fill_pair(
        Odometry,
        "gz.msgs.Odometry",
        fields(FRAMES, ("pose.pose", "pose", POSE), ("twist.twist", "twist", TWIST)),
    ),
    fill_pair(
        Odometry,
        "gz.msgs.OdometryWithCovariance",
        fields(
            FRAMES,
            ("pose", "pose_with_covariance", POSE_WITH_COVARIANCE),
            ("twist", "twist_with_covariance", TWIST_WITH_COVARIANCE),
        ),
    ),
)

"""nav_msgs/msg/Odometry with gz.msgs.Odometry and gz.msgs.OdometryWithCovariance.

The rules: docs/conversions-per-package.md §3.4.
"""

from __future__ import annotations

from typing import Any

from nav_msgs.msg import Odometry

from ros_gz_bridge_py.converters.nav_msgs import PAIRS

ODOMETRY, ODOMETRY_WITH_COVARIANCE = PAIRS
COVARIANCE = [i + 0.25 for i in range(36)]


def sample() -> Any:
    ros = Odometry(child_frame_id="base_link")
    ros.header.frame_id = "odom"
    ros.header.stamp.sec, ros.header.stamp.nanosec = 5, 6
    ros.pose.pose.position.x, ros.pose.pose.orientation.z = 1.5, 0.5
    ros.twist.twist.linear.y, ros.twist.twist.angular.z = -2.25, 3.125
    ros.pose.covariance = COVARIANCE
    ros.twist.covariance = list(reversed(COVARIANCE))
    return ros


def test_gz_odometry_is_the_default_and_drops_covariances() -> None:
    assert ODOMETRY.gz_type == "gz.msgs.Odometry"
    gz = ODOMETRY.to_gz(sample())
    assert [(d.key, list(d.value)) for d in gz.header.data] == [
        ("frame_id", ["odom"]),
        ("child_frame_id", ["base_link"]),
    ]
    assert gz.HasField("pose")
    assert gz.HasField("twist")
    assert not gz.pose.HasField("header")
    ros = ODOMETRY.to_ros(gz)
    expected = sample()
    expected.pose.covariance = [0.0] * 36
    expected.twist.covariance = [0.0] * 36
    assert ros == expected


def test_odometry_with_covariance_round_trips() -> None:
    assert ODOMETRY_WITH_COVARIANCE.gz_type == "gz.msgs.OdometryWithCovariance"
    gz = ODOMETRY_WITH_COVARIANCE.to_gz(sample())
    assert list(gz.pose_with_covariance.covariance.data) == COVARIANCE
    assert ODOMETRY_WITH_COVARIANCE.to_ros(gz) == sample()


def test_child_frame_id_scopes_become_slashes() -> None:
    gz = ODOMETRY.to_gz(Odometry(child_frame_id="robot::base"))
    assert ODOMETRY.to_ros(gz).child_frame_id == "robot/base"

"""trajectory_msgs/msg/JointTrajectory <-> gz.msgs.JointTrajectory (docs/conversions-per-package.md
§3.9)."""

from __future__ import annotations

from typing import Any

import pytest
from trajectory_msgs.msg import JointTrajectory, JointTrajectoryPoint

from ros_gz_bridge_py.converters.trajectory_msgs import (
    joint_trajectory_to_gz,
    joint_trajectory_to_ros,
    normalize_duration,
)
from ros_gz_bridge_py.msgs import message_class

GzJointTrajectory = message_class("gz.msgs.JointTrajectory")

INT32_MAX = 2**31 - 1
INT32_MIN = -(2**31)


def upstream_trajectory() -> Any:
    """The upstream fixture: 7 joints, 10 points of 1.1i, 2.2i, 3.3i, 4.4i."""
    ros = JointTrajectory()
    ros.header.stamp.sec = 2
    ros.header.stamp.nanosec = 3
    ros.header.frame_id = "frame_id_value"
    ros.joint_names = [f"joint_{i}" for i in range(7)]
    points = []
    for i in range(10):
        point = JointTrajectoryPoint()
        point.positions = [1.1 * i] * 7
        point.velocities = [2.2 * i] * 7
        point.accelerations = [3.3 * i] * 7
        point.effort = [4.4 * i] * 7
        point.time_from_start.sec = 12345
        point.time_from_start.nanosec = 67890
        points.append(point)
    ros.points = points
    return ros


def test_upstream_fixture_converts_to_gz() -> None:
    gz = joint_trajectory_to_gz(upstream_trajectory())
    assert (gz.header.stamp.sec, gz.header.stamp.nsec) == (2, 3)
    assert [(d.key, list(d.value)) for d in gz.header.data] == [("frame_id", ["frame_id_value"])]
    assert list(gz.joint_names) == [f"joint_{i}" for i in range(7)]
    assert len(gz.points) == 10
    for i, point in enumerate(gz.points):
        assert list(point.positions) == [1.1 * i] * 7
        assert list(point.velocities) == [2.2 * i] * 7
        assert list(point.accelerations) == [3.3 * i] * 7
        assert list(point.effort) == [4.4 * i] * 7
        assert point.HasField("time_from_start")
        assert not point.time_from_start.HasField("header")
        assert (point.time_from_start.sec, point.time_from_start.nsec) == (12345, 67890)


def test_round_trip_is_exact() -> None:
    ros = upstream_trajectory()
    back = joint_trajectory_to_ros(joint_trajectory_to_gz(ros))
    assert back == ros


def test_ragged_point_lists_keep_their_lengths() -> None:
    ros = JointTrajectory()
    point = JointTrajectoryPoint()
    point.positions = [1.5, -2.25, 3.125]
    point.velocities = [0.5]
    point.effort = [7.75, 8.5]
    ros.points = [point]
    gz = joint_trajectory_to_gz(ros)
    assert list(gz.points[0].positions) == [1.5, -2.25, 3.125]
    assert list(gz.points[0].velocities) == [0.5]
    assert list(gz.points[0].accelerations) == []
    assert list(gz.points[0].effort) == [7.75, 8.5]
    back = joint_trajectory_to_ros(gz).points[0]
    assert list(back.positions) == [1.5, -2.25, 3.125]
    assert list(back.velocities) == [0.5]
    assert list(back.accelerations) == []
    assert list(back.effort) == [7.75, 8.5]


def test_empty_trajectory_still_has_a_header() -> None:
    gz = joint_trajectory_to_gz(JointTrajectory())
    assert gz.HasField("header")
    assert gz.header.HasField("stamp")
    assert len(gz.points) == 0


def test_r2g_nanosec_is_reinterpreted_as_int32() -> None:
    ros = JointTrajectory()
    point = JointTrajectoryPoint()
    point.time_from_start.sec = -4
    point.time_from_start.nanosec = 3_000_000_000
    ros.points = [point]
    duration = joint_trajectory_to_gz(ros).points[0].time_from_start
    assert (duration.sec, duration.nsec) == (-4, 3_000_000_000 - 2**32)


def test_g2r_normalises_the_duration() -> None:
    gz = GzJointTrajectory()
    point = gz.points.add()
    point.time_from_start.sec = 5
    point.time_from_start.nsec = 2_500_000_000 - 2**32  # uint32 2.5e9 once reinterpreted
    ros = joint_trajectory_to_ros(gz)
    assert (ros.points[0].time_from_start.sec, ros.points[0].time_from_start.nanosec) == (
        7,
        500_000_000,
    )


def test_g2r_absent_duration_reads_as_zero() -> None:
    gz = GzJointTrajectory()
    gz.points.add()
    duration = joint_trajectory_to_ros(gz).points[0].time_from_start
    assert (duration.sec, duration.nanosec) == (0, 0)


@pytest.mark.parametrize(
    ("sec", "nsec", "expected"),
    [
        (1, 2, (1, 2)),
        (1, 1_000_000_001, (2, 1)),
        (-1, 500, (-1, 500)),
        (-3, 1_500_000_000, (-2, 500_000_000)),
        # int32 wrap of the seconds before normalising
        (2**32 + 9, 0, (9, 0)),
        # negative nsec is read as a large uint32
        (0, -1, (4, 294_967_295)),
        # carry past INT32_MAX saturates
        (INT32_MAX, -1, (INT32_MAX, 2**32 - 1)),
        (INT32_MAX, 999_999_999, (INT32_MAX, 999_999_999)),
        (INT32_MIN, 0, (INT32_MIN, 0)),
        (INT32_MIN, 1, (INT32_MIN, 1)),
    ],
)
def test_normalize_duration(sec: int, nsec: int, expected: tuple[int, int]) -> None:
    assert normalize_duration(sec, nsec) == expected

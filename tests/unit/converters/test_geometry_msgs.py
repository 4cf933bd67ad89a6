"""geometry_msgs pairs (docs/conversions.md §1.4, §1.5; docs/conversions-per-package.md §3.3)."""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest
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

from ros_gz_bridge_py.converters.geometry_msgs import PAIRS
from ros_gz_bridge_py.converters.registry import Pair
from ros_gz_bridge_py.msgs import message_class

BY_KEY = {(p.ros_type.rsplit("/", 1)[1], p.gz_type): p for p in PAIRS}
COVARIANCE = [i + 0.5 for i in range(36)]  # exact in float32


def pair(ros_name: str, gz_type: str) -> Pair:
    return BY_KEY[(ros_name, gz_type)]


def header_entries(gz_header: Any) -> list[tuple[str, list[str]]]:
    return [(d.key, list(d.value)) for d in gz_header.data]


def sample_pose() -> Any:
    return Pose(
        position=Point(x=1.5, y=-2.25, z=3.125),
        orientation=Quaternion(x=0.1, y=0.2, z=0.3, w=0.4),
    )


def sample_twist() -> Any:
    return Twist(linear=Vector3(x=1.0, y=2.0, z=3.0), angular=Vector3(x=-4.0, y=-5.0, z=-6.0))


def stamp(msg: Any, frame: str) -> Any:
    msg.header.stamp.sec, msg.header.stamp.nanosec, msg.header.frame_id = 10, 20, frame
    return msg


def test_every_geometry_pair_of_the_index_is_declared() -> None:
    assert len(PAIRS) == len(BY_KEY) == 16


@pytest.mark.parametrize(
    ("ros_msg", "gz_type"),
    [
        (Point(x=1.5, y=-2.25, z=3.125), "gz.msgs.Vector3d"),
        (Vector3(x=-1.5, y=2.25, z=-3.125), "gz.msgs.Vector3d"),
        (Quaternion(x=1.0, y=2.0, z=3.0, w=4.0), "gz.msgs.Quaternion"),
        (sample_pose(), "gz.msgs.Pose"),
        (sample_twist(), "gz.msgs.Twist"),
        (Wrench(force=Vector3(x=1.0, y=2.0, z=3.0), torque=Vector3(z=9.0)), "gz.msgs.Wrench"),
        (
            PoseWithCovariance(pose=sample_pose(), covariance=COVARIANCE),
            "gz.msgs.PoseWithCovariance",
        ),
        (
            TwistWithCovariance(twist=sample_twist(), covariance=COVARIANCE),
            "gz.msgs.TwistWithCovariance",
        ),
        (stamp(PoseStamped(pose=sample_pose()), "map"), "gz.msgs.Pose"),
        (stamp(TwistStamped(twist=sample_twist()), "base"), "gz.msgs.Twist"),
        (stamp(WrenchStamped(wrench=Wrench(force=Vector3(x=7.0))), "tool"), "gz.msgs.Wrench"),
        (stamp(PoseArray(poses=[sample_pose(), Pose()]), "odom"), "gz.msgs.Pose_V"),
        (
            stamp(PoseWithCovarianceStamped(pose=PoseWithCovariance(pose=sample_pose())), "m"),
            "gz.msgs.PoseWithCovariance",
        ),
        (
            stamp(TwistWithCovarianceStamped(twist=TwistWithCovariance(twist=sample_twist())), "t"),
            "gz.msgs.TwistWithCovariance",
        ),
    ],
)
def test_lossless_pairs_round_trip(ros_msg: Any, gz_type: str) -> None:
    conv = pair(type(ros_msg).__name__, gz_type)
    gz = conv.to_gz(ros_msg)
    assert gz.DESCRIPTOR.full_name == gz_type
    assert conv.to_ros(gz) == ros_msg


def test_pose_to_gz_sets_no_header_name_or_id_and_keeps_default_submessages() -> None:
    gz = pair("Pose", "gz.msgs.Pose").to_gz(Pose())
    assert gz.HasField("position")
    assert gz.HasField("orientation")
    assert gz.orientation.w == 1.0
    assert not gz.HasField("header")
    assert (gz.name, gz.id) == ("", 0)


def test_twist_and_wrench_default_submessages_are_present() -> None:
    twist = pair("Twist", "gz.msgs.Twist").to_gz(Twist())
    assert twist.HasField("linear")
    assert twist.HasField("angular")
    wrench = pair("Wrench", "gz.msgs.Wrench").to_gz(Wrench())
    assert wrench.HasField("force")
    assert wrench.HasField("torque")
    assert not wrench.HasField("force_offset")


def test_absent_gz_orientation_reads_as_all_zero_quaternion() -> None:
    ros = pair("Pose", "gz.msgs.Pose").to_ros(message_class("gz.msgs.Pose")())
    assert (ros.orientation.x, ros.orientation.w) == (0.0, 0.0)


def test_covariance_is_float32_on_the_wire() -> None:
    ros = PoseWithCovariance(covariance=[0.1] * 36)
    gz = pair("PoseWithCovariance", "gz.msgs.PoseWithCovariance").to_gz(ros)
    assert len(gz.covariance.data) == 36
    assert gz.covariance.data[0] == pytest.approx(0.1, rel=1e-7)
    assert gz.covariance.data[0] == float(np.float32(0.1))


@pytest.mark.parametrize("size", [0, 35, 37])
def test_covariance_of_wrong_size_reads_as_zeros(size: int) -> None:
    gz = message_class("gz.msgs.TwistWithCovariance")()
    gz.covariance.data.extend([1.0] * size)
    ros = pair("TwistWithCovariance", "gz.msgs.TwistWithCovariance").to_ros(gz)
    assert list(ros.covariance) == [0.0] * 36


def test_stamped_covariance_headers_live_inside_the_gz_submessage() -> None:
    ros = stamp(PoseWithCovarianceStamped(), "map")
    gz = pair("PoseWithCovarianceStamped", "gz.msgs.PoseWithCovariance").to_gz(ros)
    assert header_entries(gz.pose.header) == [("frame_id", ["map"])]
    ros2 = stamp(TwistWithCovarianceStamped(), "base")
    gz2 = pair("TwistWithCovarianceStamped", "gz.msgs.TwistWithCovariance").to_gz(ros2)
    assert header_entries(gz2.twist.header) == [("frame_id", ["base"])]


def test_pose_array_poses_have_no_header() -> None:
    gz = pair("PoseArray", "gz.msgs.Pose_V").to_gz(stamp(PoseArray(poses=[sample_pose()]), "o"))
    assert header_entries(gz.header) == [("frame_id", ["o"])]
    assert not gz.pose[0].HasField("header")


def test_transform_stamped_header_entries_and_child_frame() -> None:
    ros = stamp(TransformStamped(child_frame_id="child"), "parent")
    ros.transform = Transform(
        translation=Vector3(x=1.0, y=2.0, z=3.0), rotation=Quaternion(x=1.0, y=2.0, z=3.0, w=4.0)
    )
    conv = pair("TransformStamped", "gz.msgs.Pose")
    gz = conv.to_gz(ros)
    assert header_entries(gz.header) == [("frame_id", ["parent"]), ("child_frame_id", ["child"])]
    assert (gz.position.x, gz.orientation.w) == (1.0, 4.0)
    assert conv.to_ros(gz) == ros


def test_transform_stamped_to_ros_takes_first_child_frame_id_and_converts_scopes() -> None:
    gz = message_class("gz.msgs.Pose")(name="ignored")
    gz.header.data.add(key="seq", value=["1"])
    gz.header.data.add(key="frame_id", value=["world"])
    gz.header.data.add(key="child_frame_id", value=["robot::base"])
    gz.header.data.add(key="child_frame_id", value=["second"])
    ros = pair("TransformStamped", "gz.msgs.Pose").to_ros(gz)
    assert (ros.header.frame_id, ros.child_frame_id) == ("world", "robot/base")


def test_pose_stamped_ignores_child_frame_id() -> None:
    gz = message_class("gz.msgs.Pose")()
    gz.header.data.add(key="child_frame_id", value=["c"])
    assert pair("PoseStamped", "gz.msgs.Pose").to_ros(gz).header.frame_id == ""


def test_transform_without_header() -> None:
    gz = pair("Transform", "gz.msgs.Pose").to_gz(Transform())
    assert not gz.HasField("header")

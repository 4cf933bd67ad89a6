"""The table machinery the converters share: one declaration, both directions."""

from __future__ import annotations

from array import array

from geometry_msgs.msg import Point, Pose, PoseArray, PoseStamped
from ros_gz_interfaces.msg import Contact, JointWrench

from ros_gz_bridge_py.converters._fields import (
    TO_GZ_ONLY,
    WHOLE,
    Value,
    converters,
    each,
    fields,
    numbers,
)
from ros_gz_bridge_py.converters.geometry_msgs import POSE, VECTOR3
from ros_gz_bridge_py.msgs import message_class


def test_plain_renamed_and_nested_entries_go_both_ways() -> None:
    to_gz, to_ros = converters(
        fields(("position", VECTOR3), ("orientation", "orientation", fields("x", ("w", "w")))),
        Pose,
        "gz.msgs.Pose",
    )
    ros = Pose()
    ros.position.x, ros.position.y, ros.position.z = 1.5, 2.5, 3.5
    ros.orientation.x, ros.orientation.y, ros.orientation.w = 0.25, 0.75, 0.5
    gz = to_gz(ros)
    assert (gz.position.x, gz.position.y, gz.position.z) == (1.5, 2.5, 3.5)
    assert (gz.orientation.x, gz.orientation.y, gz.orientation.w) == (0.25, 0.0, 0.5)
    back = to_ros(gz)
    assert (back.position.x, back.position.y, back.position.z) == (1.5, 2.5, 3.5)
    assert (back.orientation.x, back.orientation.y, back.orientation.w) == (0.25, 0.0, 0.5)


def test_whole_fills_the_gz_message_itself_and_dotted_paths_reach_into_fields() -> None:
    to_gz, to_ros = converters(
        fields(("header.frame_id", "name"), ("pose", WHOLE, POSE)), PoseStamped, "gz.msgs.Pose"
    )
    ros = PoseStamped()
    ros.header.frame_id = "base"
    ros.pose.position.x = 4.0
    gz = to_gz(ros)
    assert (gz.name, gz.position.x) == ("base", 4.0)
    back = to_ros(gz)
    assert (back.header.frame_id, back.pose.position.x) == ("base", 4.0)


def test_values_convert_each_way_and_none_leaves_the_target_alone() -> None:
    halve_double = Value(lambda v: v / 2, lambda v: v * 2)
    to_gz, to_ros = converters(
        fields(("x", halve_double), ("y", TO_GZ_ONLY), ("z", Value(None, lambda v: v + 1))),
        Point,
        "gz.msgs.Vector3d",
    )
    gz = to_gz(Point(x=8.0, y=3.0, z=5.0))
    assert (gz.x, gz.y, gz.z) == (4.0, 3.0, 0.0)
    back = to_ros(gz)
    assert (back.x, back.y, back.z) == (8.0, 0.0, 1.0)


def test_each_adds_one_gz_element_per_item_and_replaces_the_ros_list() -> None:
    to_gz, to_ros = converters(
        fields(("poses", "pose", each(POSE, Pose))), PoseArray, "gz.msgs.Pose_V"
    )
    ros = PoseArray(poses=[Pose(), Pose()])
    ros.poses[1].position.z = 9.0
    gz = to_gz(ros)
    assert [p.position.z for p in gz.pose] == [0.0, 9.0]
    back = to_ros(gz)
    assert [p.position.z for p in back.poses] == [0.0, 9.0]
    assert all(isinstance(p, Pose) for p in back.poses)


def test_numbers_read_the_gz_values_into_a_ros_array() -> None:
    fill = fields(
        ("depths", "depth", numbers("d")), ("wrenches", "wrench", each(fields(), JointWrench))
    )
    gz = message_class("gz.msgs.Contact")()
    ros = Contact(depths=[0.5, -1.25])
    fill.to_gz(ros, gz)
    assert list(gz.depth) == [0.5, -1.25]
    back = Contact()
    fill.to_ros(gz, back)
    assert back.depths == array("d", [0.5, -1.25])
    assert back.wrenches == []

"""ros_gz_interfaces AirSpeed and LogicalCameraImage, both directions, every field distinct."""

from __future__ import annotations

from typing import Any

from geometry_msgs.msg import Pose
from ros_gz_interfaces.msg import AirSpeed, LogicalCameraImage, LogicalCameraImageModel
from std_msgs.msg import Header

from ros_gz_bridge_py.converters import default_registry
from ros_gz_bridge_py.converters import ros_gz_interfaces_sensors as conv
from ros_gz_bridge_py.msgs import message_class

GzAirSpeed = message_class("gz.msgs.AirSpeed")
GzLogicalCameraImage = message_class("gz.msgs.LogicalCameraImage")


def header(sec: int, nanosec: int, frame: str) -> Any:
    ros = Header(frame_id=frame)
    ros.stamp.sec, ros.stamp.nanosec = sec, nanosec
    return ros


def gz_header(gz: Any, sec: int, nsec: int, frame: str) -> None:
    gz.stamp.sec, gz.stamp.nsec = sec, nsec
    entry = gz.data.add()
    entry.key = "frame_id"
    entry.value.append(frame)


def header_of(gz: Any) -> tuple[int, int, list[tuple[str, list[str]]]]:
    return gz.stamp.sec, gz.stamp.nsec, [(e.key, list(e.value)) for e in gz.data]


def pose(base: float) -> Any:
    """A pose whose seven numbers all differ (and differ from other bases)."""
    ros = Pose()
    ros.position.x, ros.position.y, ros.position.z = base, base + 0.5, base + 0.25
    o = ros.orientation
    o.x, o.y, o.z, o.w = base + 0.125, base + 0.375, base + 0.625, base + 0.875
    return ros


def pose_numbers(p: Any) -> tuple[float, ...]:
    """The seven numbers of a ROS or gz pose, position then orientation."""
    return (
        p.position.x, p.position.y, p.position.z,
        p.orientation.x, p.orientation.y, p.orientation.z, p.orientation.w,
    )  # fmt: skip


def test_both_pairs_are_registered_with_these_converters() -> None:
    registry = default_registry()
    air = registry.get("ros_gz_interfaces/msg/AirSpeed", "gz.msgs.AirSpeed")
    assert (air.to_gz, air.to_ros) == (conv.air_speed_to_gz, conv.air_speed_to_ros)
    # The Fortress name reaches the same pair.
    camera = registry.get(
        "ros_gz_interfaces/msg/LogicalCameraImage", "ignition.msgs.LogicalCameraImage"
    )
    assert camera.to_ros is conv.logical_camera_image_to_ros
    assert camera.to_gz is conv.logical_camera_image_to_gz


# --- AirSpeed -------------------------------------------------------------------------------


def test_air_speed_to_gz_keeps_pressure_and_temperature_apart() -> None:
    ros = AirSpeed(header=header(11, 12, "pitot"), diff_pressure=6.125, temperature=288.15)
    gz = conv.air_speed_to_gz(ros)
    assert header_of(gz.header) == (11, 12, [("frame_id", ["pitot"])])
    assert (gz.diff_pressure, gz.temperature) == (6.125, 288.15)


def test_air_speed_to_ros_keeps_pressure_and_temperature_apart() -> None:
    gz = GzAirSpeed(diff_pressure=-0.75, temperature=251.5)
    gz_header(gz.header, 21, 22, "plane::pitot")
    ros = conv.air_speed_to_ros(gz)
    assert isinstance(ros, AirSpeed)
    assert (ros.header.stamp.sec, ros.header.stamp.nanosec) == (21, 22)
    assert ros.header.frame_id == "plane/pitot"
    assert (ros.diff_pressure, ros.temperature) == (-0.75, 251.5)


def test_default_air_speed_sends_its_header() -> None:
    gz = conv.air_speed_to_gz(AirSpeed())
    assert gz.HasField("header")
    assert gz.header.HasField("stamp")


# --- LogicalCameraImage ---------------------------------------------------------------------


def camera_image() -> Any:
    return LogicalCameraImage(
        header=header(31, 32, "camera_link"),
        pose=pose(1.0),
        model=[
            LogicalCameraImageModel(name="box", pose=pose(10.0)),
            LogicalCameraImageModel(name="shelf::top", pose=pose(20.0)),
            LogicalCameraImageModel(name="", pose=pose(30.0)),
        ],
    )


def test_logical_camera_image_to_gz_converts_camera_pose_and_each_model_in_order() -> None:
    gz = conv.logical_camera_image_to_gz(camera_image())
    assert header_of(gz.header) == (31, 32, [("frame_id", ["camera_link"])])
    assert pose_numbers(gz.pose) == (1.0, 1.5, 1.25, 1.125, 1.375, 1.625, 1.875)
    assert [m.name for m in gz.model] == ["box", "shelf::top", ""]
    assert pose_numbers(gz.model[0].pose) == (10.0, 10.5, 10.25, 10.125, 10.375, 10.625, 10.875)
    assert pose_numbers(gz.model[1].pose) == (20.0, 20.5, 20.25, 20.125, 20.375, 20.625, 20.875)
    assert pose_numbers(gz.model[2].pose) == (30.0, 30.5, 30.25, 30.125, 30.375, 30.625, 30.875)
    for gz_pose in (gz.pose, *(m.pose for m in gz.model)):
        assert not gz_pose.HasField("header")
        assert (gz_pose.name, gz_pose.id) == ("", 0)


def test_logical_camera_image_to_ros_converts_camera_pose_and_each_model_in_order() -> None:
    gz = GzLogicalCameraImage()
    gz_header(gz.header, 41, 42, "robot::camera")
    gz.pose.position.x, gz.pose.position.y, gz.pose.position.z = -1.0, -2.0, -3.0
    gz.pose.orientation.x, gz.pose.orientation.w = 0.6, 0.8
    first = gz.model.add(name="cone_yellow")
    first.pose.position.x, first.pose.position.y, first.pose.position.z = 4.5, 5.5, 6.5
    first.pose.orientation.z, first.pose.orientation.w = -0.6, 0.8
    gz.model.add(name="cone_blue").pose.position.y = 7.25
    ros = conv.logical_camera_image_to_ros(gz)
    assert isinstance(ros, LogicalCameraImage)
    assert (ros.header.stamp.sec, ros.header.stamp.nanosec, ros.header.frame_id) == (
        41,
        42,
        "robot/camera",
    )
    assert pose_numbers(ros.pose) == (-1.0, -2.0, -3.0, 0.6, 0.0, 0.0, 0.8)
    assert [m.name for m in ros.model] == ["cone_yellow", "cone_blue"]
    assert pose_numbers(ros.model[0].pose) == (4.5, 5.5, 6.5, 0.0, 0.0, -0.6, 0.8)
    # No orientation on the wire: proto3 w is 0, not the ROS identity (docs/conversions.md §1.4).
    assert pose_numbers(ros.model[1].pose) == (0.0, 7.25, 0.0, 0.0, 0.0, 0.0, 0.0)


def test_logical_camera_image_round_trips() -> None:
    ros = camera_image()
    assert conv.logical_camera_image_to_ros(conv.logical_camera_image_to_gz(ros)) == ros


def test_default_logical_camera_image_has_header_and_pose_and_no_model() -> None:
    gz = conv.logical_camera_image_to_gz(LogicalCameraImage())
    assert gz.HasField("header")
    assert gz.pose.HasField("position")
    assert gz.pose.HasField("orientation")
    assert gz.pose.orientation.w == 1.0
    assert len(gz.model) == 0

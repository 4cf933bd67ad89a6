"""Builders of ros_gz_interfaces messages with a distinct value in every field, and the checks of
the Gazebo side they share (the tests of ``converters/ros_gz_interfaces*.py``)."""

from __future__ import annotations

from typing import Any

from geometry_msgs.msg import Pose, Vector3
from ros_gz_interfaces.msg import (
    Entity,
    JointWrench,
    TrackVisual,
)
from std_msgs.msg import ColorRGBA, Header

from ros_gz_bridge_py.msgs import message_class

GzAny = message_class("gz.msgs.Any")
GzBoolean = message_class("gz.msgs.Boolean")
GzDataframe = message_class("gz.msgs.Dataframe")
GzEntity = message_class("gz.msgs.Entity")
GzLight = message_class("gz.msgs.Light")
GzLogPlaybackStatistics = message_class("gz.msgs.LogPlaybackStatistics")
GzMaterialColor = message_class("gz.msgs.MaterialColor")
GzParam = message_class("gz.msgs.Param")
GzParamV = message_class("gz.msgs.Param_V")
GzSensorNoise = message_class("gz.msgs.SensorNoise")


def header(sec: int = 2, frame: str = "frame_id_value") -> Any:
    ros = Header(frame_id=frame)
    ros.stamp.sec = sec
    ros.stamp.nanosec = 3
    return ros


def vec(x: float, y: float, z: float) -> Any:
    return Vector3(x=x, y=y, z=z)


def pose(base: float) -> Any:
    ros = Pose()
    ros.position.x, ros.position.y, ros.position.z = base, base + 0.5, base + 0.25
    o = ros.orientation
    o.x, o.y, o.z, o.w = base + 1, base + 2, base + 3, base + 4
    return ros


def color(base: float) -> Any:
    return ColorRGBA(r=base, g=base + 0.125, b=base + 0.25, a=base + 0.375)


def entity(id_: int = 9_000_000_001, name: str = "box::link", kind: int = Entity.LINK) -> Any:
    return Entity(id=id_, name=name, type=kind)


def joint_wrench(base: float) -> Any:
    ros = JointWrench(header=header(int(base)))
    ros.body_1_name.data = f"body1_{base}"
    ros.body_1_id.data = int(base) + 11
    ros.body_2_name.data = f"body2_{base}"
    ros.body_2_id.data = int(base) + 22
    ros.body_1_wrench.force = vec(base, -base, 2 * base)
    ros.body_1_wrench.torque = vec(base + 0.5, -base - 0.5, 3 * base)
    ros.body_2_wrench.force = vec(base + 0.25, base - 0.75, 4 * base)
    ros.body_2_wrench.torque = vec(base + 0.125, base - 0.375, 5 * base)
    return ros


def track_visual() -> Any:
    return TrackVisual(
        header=header(5, "tracked"),
        name="visual_name",
        id=4242,
        inherit_orientation=True,
        min_dist=1.5,
        max_dist=22.25,
        is_static=True,
        use_model_frame=True,
        xyz=vec(0.5, -1.5, 2.5),
        inherit_yaw=True,
    )


def header_data(gz_header: Any) -> list[tuple[str, list[str]]]:
    return [(entry.key, list(entry.value)) for entry in gz_header.data]


def assert_stamped(gz_header: Any, sec: int = 2, frame: str = "frame_id_value") -> None:
    assert gz_header.HasField("stamp")
    assert (gz_header.stamp.sec, gz_header.stamp.nsec) == (sec, 3)
    assert header_data(gz_header) == [("frame_id", [frame])]


def assert_vector(gz: Any, x: float, y: float, z: float) -> None:
    assert (gz.x, gz.y, gz.z) == (x, y, z)

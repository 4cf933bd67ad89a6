"""Converters for two ros_gz_interfaces sensor messages: AirSpeed and LogicalCameraImage.

The pair table lives in ``ros_gz_interfaces``. Both conversions copy field by field, as the
reference does (ros_gz PR #698 for LogicalCameraImage, PR #914 for AirSpeed, whose description
states the mapping: header, diff_pressure, temperature).

``gz.msgs.AirSpeed`` exists from Harmonic (gz-msgs 10) on; ``LogicalCameraImage`` also in
Fortress, under ``ignition.msgs.LogicalCameraImage`` with the same fields.

Differences from ros_gz_bridge: none known. As for every pose (docs/conversions.md §1.4), a gz
orientation that is absent reads as the quaternion (0, 0, 0, 0), not the identity.
"""

from __future__ import annotations

from ros_gz_interfaces.msg import AirSpeed, LogicalCameraImage, LogicalCameraImageModel

from ros_gz_bridge_py.converters._fields import converters, each, fields
from ros_gz_bridge_py.converters.geometry_msgs import POSE
from ros_gz_bridge_py.converters.std_msgs import HEADER

air_speed_to_gz, air_speed_to_ros = converters(
    fields(("header", HEADER), "diff_pressure", "temperature"), AirSpeed, "gz.msgs.AirSpeed"
)

#: Header, the camera pose and one gz ``model`` per ROS model, in order. Every pose has its
#: position and orientation present; gz pose header, name and id stay unset.
logical_camera_image_to_gz, logical_camera_image_to_ros = converters(
    fields(
        ("header", HEADER),
        ("pose", POSE),
        ("model", each(fields("name", ("pose", POSE)), LogicalCameraImageModel)),
    ),
    LogicalCameraImage,
    "gz.msgs.LogicalCameraImage",
)

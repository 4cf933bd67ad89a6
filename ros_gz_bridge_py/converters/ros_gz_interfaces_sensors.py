"""Converters for two ros_gz_interfaces sensor messages: AirSpeed and LogicalCameraImage.

The pair table lives in ``ros_gz_interfaces``. Both conversions copy field by field, as the
reference does (ros_gz PR #698 for LogicalCameraImage, PR #914 for AirSpeed, whose description
states the mapping: header, diff_pressure, temperature).

``gz.msgs.AirSpeed`` exists from Harmonic (gz-msgs 10) on; ``LogicalCameraImage`` also in
Fortress, under ``ignition.msgs.LogicalCameraImage`` with the same fields.

Differences from ros_gz_bridge: none known. As for every pose (conversions.md §1.4), a gz
orientation that is absent reads as the quaternion (0, 0, 0, 0), not the identity.
"""

from __future__ import annotations

from typing import Any

from ros_gz_interfaces.msg import AirSpeed, LogicalCameraImage, LogicalCameraImageModel

from ros_gz_bridge_py.converters._fields import converters, fields
from ros_gz_bridge_py.converters.geometry_msgs import POSE
from ros_gz_bridge_py.converters.std_msgs import HEADER
from ros_gz_bridge_py.msgs import message_class

_GzLogicalCameraImage = message_class("gz.msgs.LogicalCameraImage")

air_speed_to_gz, air_speed_to_ros = converters(
    fields(("header", HEADER), "diff_pressure", "temperature"), AirSpeed, "gz.msgs.AirSpeed"
)


def logical_camera_image_to_gz(ros: Any) -> Any:
    """Header, the camera pose and one gz ``model`` per ROS model, in order.

    Every pose has its position and orientation present; gz pose header, name and id stay unset.
    """
    gz = _GzLogicalCameraImage()
    HEADER.to_gz(ros.header, gz.header)
    POSE.to_gz(ros.pose, gz.pose)
    for model in ros.model:
        gz_model = gz.model.add()
        gz_model.name = model.name
        POSE.to_gz(model.pose, gz_model.pose)
    return gz


def _ros_model(gz_model: Any) -> Any:
    model = LogicalCameraImageModel(name=gz_model.name)
    POSE.to_ros(gz_model.pose, model.pose)
    return model


def logical_camera_image_to_ros(gz: Any) -> Any:
    ros = LogicalCameraImage()
    HEADER.to_ros(gz.header, ros.header)
    POSE.to_ros(gz.pose, ros.pose)
    ros.model = [_ros_model(gz_model) for gz_model in gz.model]
    return ros

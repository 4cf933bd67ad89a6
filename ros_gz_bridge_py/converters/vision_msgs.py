"""vision_msgs Detection2D/3D(Array) <-> gz.msgs.AnnotatedAxisAligned2DBox/Oriented3DBox(_V).

conversions.md §3.11, vision_msgs 4.x layout. Only ``results[0].hypothesis.class_id`` survives,
parsed as an integer label like C++ ``std::stoi``; G→R reports one hypothesis with score 1.0.

Differences from ros_gz_bridge:
- A class_id that ``std::stoi`` rejects (empty, non-numeric, outside int32) raises
  ConversionError naming it; the reference lets the exception escape (likely termination).
"""

from __future__ import annotations

import re
from typing import Any

from vision_msgs.msg import (
    Detection2D,
    Detection2DArray,
    Detection3D,
    Detection3DArray,
    ObjectHypothesisWithPose,
)

from ros_gz_bridge_py.converters.geometry_msgs import (
    fill_gz_quaternion,
    fill_gz_vector3,
    fill_ros_quaternion,
    fill_ros_vector3,
)
from ros_gz_bridge_py.converters.registry import Pair
from ros_gz_bridge_py.converters.std_msgs import fill_gz_header, fill_ros_header
from ros_gz_bridge_py.errors import ConversionError
from ros_gz_bridge_py.msgs import message_class

_Gz2DBox = message_class("gz.msgs.AnnotatedAxisAligned2DBox")
_Gz2DBoxV = message_class("gz.msgs.AnnotatedAxisAligned2DBox_V")
_Gz3DBox = message_class("gz.msgs.AnnotatedOriented3DBox")
_Gz3DBoxV = message_class("gz.msgs.AnnotatedOriented3DBox_V")

# std::stoi: optional C-locale whitespace, an optional sign, decimal digits; the rest is ignored.
_STOI_PREFIX = re.compile(r"[ \t\n\v\f\r]*([+-]?[0-9]+)")
_INT32_MIN = -(1 << 31)
_INT32_MAX = (1 << 31) - 1


def class_id_to_label(class_id: str) -> int:
    """``uint32(std::stoi(class_id))``: a negative id wraps modulo 2**32."""
    match = _STOI_PREFIX.match(class_id)
    if match is None:
        msg = f"results[0].hypothesis.class_id {class_id!r} is not an integer"
        raise ConversionError(msg)
    value = int(match.group(1))
    if not _INT32_MIN <= value <= _INT32_MAX:
        msg = f"results[0].hypothesis.class_id {class_id!r} is outside int32"
        raise ConversionError(msg)
    return value & 0xFFFFFFFF


def _label_of(ros: Any) -> int:
    return class_id_to_label(ros.results[0].hypothesis.class_id) if ros.results else 0


def _results_for(label: int) -> list[Any]:
    result = ObjectHypothesisWithPose()
    result.hypothesis.class_id = str(label)
    result.hypothesis.score = 1.0
    return [result]


def fill_gz_detection2d(ros: Any, gz: Any) -> None:
    fill_gz_header(ros.header, gz.header)
    gz.label = _label_of(ros)
    center = ros.bbox.center.position
    half_x = ros.bbox.size_x / 2
    half_y = ros.bbox.size_y / 2
    box = gz.box
    box.min_corner.x = center.x - half_x
    box.min_corner.y = center.y - half_y
    box.max_corner.x = center.x + half_x
    box.max_corner.y = center.y + half_y


def fill_ros_detection2d(gz: Any, ros: Any) -> None:
    fill_ros_header(gz.header, ros.header)
    ros.results = _results_for(gz.label)
    low = gz.box.min_corner
    high = gz.box.max_corner
    ros.bbox.center.position.x = (low.x + high.x) / 2
    ros.bbox.center.position.y = (low.y + high.y) / 2
    ros.bbox.size_x = high.x - low.x
    ros.bbox.size_y = high.y - low.y


def fill_gz_detection3d(ros: Any, gz: Any) -> None:
    fill_gz_header(ros.header, gz.header)
    gz.label = _label_of(ros)
    box = gz.box
    fill_gz_vector3(ros.bbox.center.position, box.center)
    fill_gz_vector3(ros.bbox.size, box.boxSize)
    fill_gz_quaternion(ros.bbox.center.orientation, box.orientation)


def fill_ros_detection3d(gz: Any, ros: Any) -> None:
    fill_ros_header(gz.header, ros.header)
    ros.results = _results_for(gz.label)
    box = gz.box
    fill_ros_vector3(box.center, ros.bbox.center.position)
    fill_ros_vector3(box.boxSize, ros.bbox.size)
    fill_ros_quaternion(box.orientation, ros.bbox.center.orientation)


def detection2d_to_gz(ros: Any) -> Any:
    gz = _Gz2DBox()
    fill_gz_detection2d(ros, gz)
    return gz


def detection2d_to_ros(gz: Any) -> Any:
    ros = Detection2D()
    fill_ros_detection2d(gz, ros)
    return ros


def detection2d_array_to_gz(ros: Any) -> Any:
    gz = _Gz2DBoxV()
    fill_gz_header(ros.header, gz.header)
    for detection in ros.detections:
        fill_gz_detection2d(detection, gz.annotated_box.add())
    return gz


def detection2d_array_to_ros(gz: Any) -> Any:
    ros = Detection2DArray()
    fill_ros_header(gz.header, ros.header)
    ros.detections = [detection2d_to_ros(box) for box in gz.annotated_box]
    return ros


def detection3d_to_gz(ros: Any) -> Any:
    gz = _Gz3DBox()
    fill_gz_detection3d(ros, gz)
    return gz


def detection3d_to_ros(gz: Any) -> Any:
    ros = Detection3D()
    fill_ros_detection3d(gz, ros)
    return ros


def detection3d_array_to_gz(ros: Any) -> Any:
    gz = _Gz3DBoxV()
    fill_gz_header(ros.header, gz.header)
    for detection in ros.detections:
        fill_gz_detection3d(detection, gz.annotated_box.add())
    return gz


def detection3d_array_to_ros(gz: Any) -> Any:
    ros = Detection3DArray()
    fill_ros_header(gz.header, ros.header)
    ros.detections = [detection3d_to_ros(box) for box in gz.annotated_box]
    return ros


PAIRS = (
    Pair(
        "vision_msgs/msg/Detection2D",
        "gz.msgs.AnnotatedAxisAligned2DBox",
        detection2d_to_gz,
        detection2d_to_ros,
        Detection2D,
    ),
    Pair(
        "vision_msgs/msg/Detection2DArray",
        "gz.msgs.AnnotatedAxisAligned2DBox_V",
        detection2d_array_to_gz,
        detection2d_array_to_ros,
        Detection2DArray,
    ),
    Pair(
        "vision_msgs/msg/Detection3D",
        "gz.msgs.AnnotatedOriented3DBox",
        detection3d_to_gz,
        detection3d_to_ros,
        Detection3D,
    ),
    Pair(
        "vision_msgs/msg/Detection3DArray",
        "gz.msgs.AnnotatedOriented3DBox_V",
        detection3d_array_to_gz,
        detection3d_array_to_ros,
        Detection3DArray,
    ),
)

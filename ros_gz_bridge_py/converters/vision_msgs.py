"""vision_msgs Detection2D/3D(Array) <-> gz.msgs.AnnotatedAxisAligned2DBox/Oriented3DBox(_V).

docs/conversions-per-package.md §3.11, vision_msgs 4.x layout. Only
``results[0].hypothesis.class_id`` survives, parsed as an integer label like C++ ``std::stoi``; G→R
reports one hypothesis with score 1.0.

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

from ros_gz_bridge_py.converters._fields import Fill, converters, each, fields
from ros_gz_bridge_py.converters.geometry_msgs import QUATERNION, VECTOR3
from ros_gz_bridge_py.converters.registry import Pair
from ros_gz_bridge_py.converters.std_msgs import HEADER
from ros_gz_bridge_py.errors import ConversionError

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


def _fill_gz_label(ros: Any, gz: Any) -> None:
    gz.label = class_id_to_label(ros.results[0].hypothesis.class_id) if ros.results else 0


def _fill_ros_results(gz: Any, ros: Any) -> None:
    result = ObjectHypothesisWithPose()
    result.hypothesis.class_id = str(gz.label)
    result.hypothesis.score = 1.0
    ros.results = [result]


#: ``results[0].hypothesis.class_id`` <-> gz ``label``.
_LABEL = Fill(_fill_gz_label, _fill_ros_results)


def _fill_gz_box2d(ros: Any, gz: Any) -> None:
    center = ros.bbox.center.position
    half_x = ros.bbox.size_x / 2
    half_y = ros.bbox.size_y / 2
    box = gz.box
    box.min_corner.x = center.x - half_x
    box.min_corner.y = center.y - half_y
    box.max_corner.x = center.x + half_x
    box.max_corner.y = center.y + half_y


def _fill_ros_box2d(gz: Any, ros: Any) -> None:
    low = gz.box.min_corner
    high = gz.box.max_corner
    ros.bbox.center.position.x = (low.x + high.x) / 2
    ros.bbox.center.position.y = (low.y + high.y) / 2
    ros.bbox.size_x = high.x - low.x
    ros.bbox.size_y = high.y - low.y


DETECTION2D = fields(("header", HEADER), _LABEL, Fill(_fill_gz_box2d, _fill_ros_box2d))
DETECTION3D = fields(
    ("header", HEADER),
    _LABEL,
    ("bbox.center.position", "box.center", VECTOR3),
    ("bbox.size", "box.boxSize", VECTOR3),
    ("bbox.center.orientation", "box.orientation", QUATERNION),
)

detection2d_to_gz, detection2d_to_ros = converters(
    DETECTION2D, Detection2D, "gz.msgs.AnnotatedAxisAligned2DBox"
)
detection3d_to_gz, detection3d_to_ros = converters(
    DETECTION3D, Detection3D, "gz.msgs.AnnotatedOriented3DBox"
)

detection2d_array_to_gz, detection2d_array_to_ros = converters(
    fields(("header", HEADER), ("detections", "annotated_box", each(DETECTION2D, Detection2D))),
    Detection2DArray,
    "gz.msgs.AnnotatedAxisAligned2DBox_V",
)
detection3d_array_to_gz, detection3d_array_to_ros = converters(
    fields(("header", HEADER), ("detections", "annotated_box", each(DETECTION3D, Detection3D))),
    Detection3DArray,
    "gz.msgs.AnnotatedOriented3DBox_V",
)

PAIRS = (
    Pair.of(
        Detection2D, "gz.msgs.AnnotatedAxisAligned2DBox", detection2d_to_gz, detection2d_to_ros
    ),
    Pair.of(
        Detection2DArray,
        "gz.msgs.AnnotatedAxisAligned2DBox_V",
        detection2d_array_to_gz,
        detection2d_array_to_ros,
    ),
    Pair.of(Detection3D, "gz.msgs.AnnotatedOriented3DBox", detection3d_to_gz, detection3d_to_ros),
    Pair.of(
        Detection3DArray,
        "gz.msgs.AnnotatedOriented3DBox_V",
        detection3d_array_to_gz,
        detection3d_array_to_ros,
    ),
)

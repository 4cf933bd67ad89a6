"""rcl_interfaces/msg/ParameterValue <-> gz.msgs.Any (conversions.md §3.12).

Only the scalar kinds cross: bool, integer (clamped to int32 on the way to Gazebo), double and
string. The oneof member is always set explicitly, so ``false``/``0``/``""`` still serialize.
G→R reads the member the ``type`` names; if another member is set it reads as the default.

Differences from ros_gz_bridge:
- Array parameters, and Any values of a kind ROS cannot hold (vector, color, pose, quaternion,
  time), convert to NOT_SET/NONE silently instead of printing an error.
- An integer outside int32 is clamped without printing a warning.
"""

from __future__ import annotations

from typing import Any

from rcl_interfaces.msg import ParameterType, ParameterValue

from ros_gz_bridge_py.converters.registry import Pair
from ros_gz_bridge_py.msgs import message_class

_GzAny = message_class("gz.msgs.Any")

_INT32_MIN = -(1 << 31)
_INT32_MAX = (1 << 31) - 1


def fill_gz_any(ros: Any, gz: Any) -> None:
    """Write ParameterValue ``ros`` into gz Any ``gz`` (type NONE for unsupported kinds)."""
    kind = ros.type
    if kind == ParameterType.PARAMETER_BOOL:
        gz.type = _GzAny.BOOLEAN
        gz.bool_value = ros.bool_value
    elif kind == ParameterType.PARAMETER_INTEGER:
        gz.type = _GzAny.INT32
        gz.int_value = min(max(ros.integer_value, _INT32_MIN), _INT32_MAX)
    elif kind == ParameterType.PARAMETER_DOUBLE:
        gz.type = _GzAny.DOUBLE
        gz.double_value = ros.double_value
    elif kind == ParameterType.PARAMETER_STRING:
        gz.type = _GzAny.STRING
        gz.string_value = ros.string_value
    else:
        gz.type = _GzAny.NONE


def fill_ros_parameter_value(gz: Any, ros: Any) -> None:
    """Write gz Any ``gz`` into ParameterValue ``ros`` (NOT_SET for kinds ROS cannot hold)."""
    kind = gz.type
    if kind == _GzAny.DOUBLE:
        ros.type = ParameterType.PARAMETER_DOUBLE
        ros.double_value = gz.double_value
    elif kind == _GzAny.INT32:
        ros.type = ParameterType.PARAMETER_INTEGER
        ros.integer_value = gz.int_value
    elif kind == _GzAny.STRING:
        ros.type = ParameterType.PARAMETER_STRING
        ros.string_value = gz.string_value
    elif kind == _GzAny.BOOLEAN:
        ros.type = ParameterType.PARAMETER_BOOL
        ros.bool_value = gz.bool_value
    else:
        ros.type = ParameterType.PARAMETER_NOT_SET


def parameter_value_to_gz(ros: Any) -> Any:
    gz = _GzAny()
    fill_gz_any(ros, gz)
    return gz


def parameter_value_to_ros(gz: Any) -> Any:
    ros = ParameterValue()
    fill_ros_parameter_value(gz, ros)
    return ros


PAIRS = (
    Pair(
        "rcl_interfaces/msg/ParameterValue",
        "gz.msgs.Any",
        parameter_value_to_gz,
        parameter_value_to_ros,
        ParameterValue,
    ),
)

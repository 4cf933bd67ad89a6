"""rcl_interfaces/msg/ParameterValue <-> gz.msgs.Any (docs/conversions-per-package.md §3.12).

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

from ros_gz_bridge_py.converters._fields import Fill, converters
from ros_gz_bridge_py.converters.registry import Pair
from ros_gz_bridge_py.msgs import message_class

_GzAny = message_class("gz.msgs.Any")

_INT32_MIN = -(1 << 31)
_INT32_MAX = (1 << 31) - 1

#: The kinds both sides hold: (ROS type, gz type, ROS field, gz field).
_KINDS = (
    (ParameterType.PARAMETER_BOOL, _GzAny.BOOLEAN, "bool_value", "bool_value"),
    (ParameterType.PARAMETER_INTEGER, _GzAny.INT32, "integer_value", "int_value"),
    (ParameterType.PARAMETER_DOUBLE, _GzAny.DOUBLE, "double_value", "double_value"),
    (ParameterType.PARAMETER_STRING, _GzAny.STRING, "string_value", "string_value"),
)
_BY_ROS_TYPE = {kind[0]: kind for kind in _KINDS}
_BY_GZ_TYPE = {kind[1]: kind for kind in _KINDS}


def fill_gz_any(ros: Any, gz: Any) -> None:
    """Write ParameterValue ``ros`` into gz Any ``gz`` (type NONE for unsupported kinds)."""
    kind = _BY_ROS_TYPE.get(ros.type)
    if kind is None:
        gz.type = _GzAny.NONE
        return
    _, gz_type, ros_field, gz_field = kind
    value = getattr(ros, ros_field)
    if gz_type == _GzAny.INT32:
        value = min(max(value, _INT32_MIN), _INT32_MAX)
    gz.type = gz_type
    setattr(gz, gz_field, value)


def fill_ros_parameter_value(gz: Any, ros: Any) -> None:
    """Write gz Any ``gz`` into ParameterValue ``ros`` (NOT_SET for kinds ROS cannot hold)."""
    kind = _BY_GZ_TYPE.get(gz.type)
    if kind is None:
        ros.type = ParameterType.PARAMETER_NOT_SET
        return
    ros_type, _, ros_field, gz_field = kind
    ros.type = ros_type
    setattr(ros, ros_field, getattr(gz, gz_field))


PARAMETER_VALUE = Fill(fill_gz_any, fill_ros_parameter_value)
parameter_value_to_gz, parameter_value_to_ros = converters(
    PARAMETER_VALUE, ParameterValue, "gz.msgs.Any"
)

PAIRS = (Pair.of(ParameterValue, "gz.msgs.Any", parameter_value_to_gz, parameter_value_to_ros),)

"""rcl_interfaces/msg/ParameterValue <-> gz.msgs.Any (docs/conversions-per-package.md §3.12)."""

from __future__ import annotations

from typing import Any

import pytest
from rcl_interfaces.msg import ParameterType, ParameterValue

from ros_gz_bridge_py.converters.rcl_interfaces import (
    parameter_value_to_gz,
    parameter_value_to_ros,
)
from ros_gz_bridge_py.msgs import message_class

GzAny = message_class("gz.msgs.Any")


def value(kind: int, **fields: Any) -> Any:
    return ParameterValue(type=kind, **fields)


@pytest.mark.parametrize(
    ("ros", "gz_type", "member", "expected"),
    [
        (value(ParameterType.PARAMETER_BOOL, bool_value=True), GzAny.BOOLEAN, "bool_value", True),
        (value(ParameterType.PARAMETER_INTEGER, integer_value=-42), GzAny.INT32, "int_value", -42),
        (
            value(ParameterType.PARAMETER_DOUBLE, double_value=2.75),
            GzAny.DOUBLE,
            "double_value",
            2.75,
        ),
        (
            value(ParameterType.PARAMETER_STRING, string_value="foo"),
            GzAny.STRING,
            "string_value",
            "foo",
        ),
    ],
)
def test_scalar_kinds_convert_and_round_trip(
    ros: Any, gz_type: int, member: str, expected: object
) -> None:
    gz = parameter_value_to_gz(ros)
    assert gz.type == gz_type
    assert gz.WhichOneof("value") == member
    assert getattr(gz, member) == expected
    assert not gz.HasField("header")
    assert parameter_value_to_ros(gz) == ros


@pytest.mark.parametrize(
    ("ros", "member", "wire"),
    [
        (value(ParameterType.PARAMETER_BOOL, bool_value=False), "bool_value", "10043000"),
        (value(ParameterType.PARAMETER_INTEGER, integer_value=0), "int_value", "10022000"),
        (value(ParameterType.PARAMETER_STRING, string_value=""), "string_value", "10032a00"),
    ],
)
def test_default_values_still_set_the_oneof_member(ros: Any, member: str, wire: str) -> None:
    gz = parameter_value_to_gz(ros)
    assert gz.WhichOneof("value") == member
    assert gz.SerializeToString().hex() == wire


@pytest.mark.parametrize(
    ("integer", "clamped"),
    [(2**31, 2**31 - 1), (2**63 - 1, 2**31 - 1), (-(2**31) - 1, -(2**31)), (2**31 - 1, 2**31 - 1)],
)
def test_integers_are_clamped_to_int32(integer: int, clamped: int) -> None:
    gz = parameter_value_to_gz(value(ParameterType.PARAMETER_INTEGER, integer_value=integer))
    assert gz.int_value == clamped


@pytest.mark.parametrize(
    "ros",
    [
        value(ParameterType.PARAMETER_NOT_SET),
        value(ParameterType.PARAMETER_BYTE_ARRAY, byte_array_value=[b"\x01"]),
        value(ParameterType.PARAMETER_BOOL_ARRAY, bool_array_value=[True]),
        value(ParameterType.PARAMETER_INTEGER_ARRAY, integer_array_value=[1, 2]),
        value(ParameterType.PARAMETER_DOUBLE_ARRAY, double_array_value=[1.5]),
        value(ParameterType.PARAMETER_STRING_ARRAY, string_array_value=["a"]),
        value(77),
    ],
)
def test_unsupported_kinds_become_none_with_no_value(ros: Any) -> None:
    gz = parameter_value_to_gz(ros)
    assert gz.type == GzAny.NONE
    assert gz.WhichOneof("value") is None


@pytest.mark.parametrize(
    "gz",
    [
        GzAny(type=GzAny.NONE),
        GzAny(type=GzAny.VECTOR3D, vector3d_value={"x": 1.0}),
        GzAny(type=GzAny.COLOR, color_value={"r": 0.5}),
        GzAny(type=GzAny.POSE3D),
        GzAny(type=GzAny.QUATERNIOND),
        GzAny(type=GzAny.TIME, time_value={"sec": 3}),
        GzAny(type=42, double_value=1.5),
    ],
)
def test_kinds_ros_cannot_hold_become_not_set(gz: Any) -> None:
    assert parameter_value_to_ros(gz) == ParameterValue()


def test_g2r_reads_the_member_named_by_type_even_if_another_is_set() -> None:
    ros = parameter_value_to_ros(GzAny(type=GzAny.DOUBLE, int_value=7))
    assert ros.type == ParameterType.PARAMETER_DOUBLE
    assert ros.double_value == 0.0
    assert ros.integer_value == 0

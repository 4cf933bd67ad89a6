"""ros_gz_interfaces' ParamVec as gz.msgs.Param and Param_V (converters/
ros_gz_interfaces_messages.py, docs/conversions-per-package.md §3.13): names, types, children,
order."""

from __future__ import annotations

from typing import Any

from rcl_interfaces.msg import Parameter, ParameterType, ParameterValue
from ros_gz_interfaces.msg import (
    ParamVec,
)

from ros_gz_bridge_py.converters import ros_gz_interfaces_messages as m
from tests.unit.converters.ros_gz_interfaces_values import (
    GzAny,
    GzParam,
    GzParamV,
    assert_stamped,
    header,
)

# --- ParamVec <-> Param, Param_V ------------------------------------------------------------


def string_param(name: str, text: str) -> Any:
    return Parameter(
        name=name, value=ParameterValue(type=ParameterType.PARAMETER_STRING, string_value=text)
    )


def test_param_vec_to_param_upstream_fixture() -> None:
    ros = ParamVec(
        header=header(), params=[string_param("parameter_name_foo", "parameter_value_foo")]
    )
    gz = m.param_vec_to_gz_param(ros)
    assert_stamped(gz.header)
    assert list(gz.params) == ["parameter_name_foo"]
    value = gz.params["parameter_name_foo"]
    assert (value.type, value.string_value) == (GzAny.STRING, "parameter_value_foo")
    assert len(gz.children) == 0
    assert m.param_vec_from_gz_param(gz) == ros


def test_param_vec_duplicate_name_overwrites() -> None:
    double = Parameter(
        name="dup", value=ParameterValue(type=ParameterType.PARAMETER_DOUBLE, double_value=2.5)
    )
    gz = m.param_vec_to_gz_param(ParamVec(params=[string_param("dup", "first"), double]))
    assert gz.params["dup"].WhichOneof("value") == "double_value"
    assert gz.params["dup"].double_value == 2.5


def upstream_param_tree() -> Any:
    """Map entries plus nested children, as in the upstream G→R test."""
    gz = GzParam()
    gz.params["notset_param"].type = GzAny.NONE
    child0 = gz.children.add()
    child0.params["int_param"].type = GzAny.INT32
    child0.params["int_param"].int_value = 100
    child1 = gz.children.add()
    child1.params["double_param"].type = GzAny.DOUBLE
    child1.params["double_param"].double_value = 200.5
    child2 = gz.children.add()
    child2.header.data.add(key="frame_id", value=["ignored"])
    child2.params["string_param"].type = GzAny.STRING
    child2.params["string_param"].string_value = "foo"
    grandchild = child2.children.add()
    grandchild.params["bool_param"].type = GzAny.BOOLEAN
    grandchild.params["bool_param"].bool_value = True
    return gz


def test_param_children_are_flattened_with_prefixes() -> None:
    ros = m.param_vec_from_gz_param(upstream_param_tree())
    assert [p.name for p in ros.params] == [
        "notset_param",
        "child_0/int_param",
        "child_1/double_param",
        "child_2/string_param",
        "child_2/child_0/bool_param",
    ]
    values = [p.value for p in ros.params]
    assert values[0].type == ParameterType.PARAMETER_NOT_SET
    assert (values[1].type, values[1].integer_value) == (ParameterType.PARAMETER_INTEGER, 100)
    assert values[2].double_value == 200.5
    assert values[3].string_value == "foo"
    assert (values[4].type, values[4].bool_value) == (ParameterType.PARAMETER_BOOL, True)
    assert ros.header.frame_id == ""


def test_param_map_entries_are_sorted_by_key() -> None:
    gz = GzParam()
    for key in ("zeta", "alpha", "mid"):
        gz.params[key].type = GzAny.INT32
    assert [p.name for p in m.param_vec_from_gz_param(gz).params] == ["alpha", "mid", "zeta"]


def test_param_vec_to_param_v_puts_everything_in_param_0() -> None:
    ros = ParamVec(header=header(), params=[string_param("a", "x"), string_param("b", "y")])
    gz = m.param_vec_to_gz_param_v(ros)
    assert_stamped(gz.header)
    assert len(gz.param) == 1
    assert_stamped(gz.param[0].header)
    assert sorted(gz.param[0].params) == ["a", "b"]
    back = m.param_vec_from_gz_param_v(gz)
    assert back.header == ros.header
    assert [p.name for p in back.params] == ["param_0/a", "param_0/b"]
    assert [p.value.string_value for p in back.params] == ["x", "y"]


def test_param_v_flattens_each_param_with_children() -> None:
    gz = GzParamV()
    gz.param.add().params["first"].type = GzAny.NONE
    gz.param.append(upstream_param_tree())
    names = [p.name for p in m.param_vec_from_gz_param_v(gz).params]
    assert names == [
        "param_0/first",
        "param_1/notset_param",
        "param_1/child_0/int_param",
        "param_1/child_1/double_param",
        "param_1/child_2/string_param",
        "param_1/child_2/child_0/bool_param",
    ]

"""The parameters refused at declaration, with one line naming the parameter and its range:
``service_timeout`` (an integer is taken, as for ``max_rate``), ``subscription_heartbeat`` and
the Gazebo Transport implementation (the parameter, or ``GZ_TRANSPORT_IMPLEMENTATION``)."""

from __future__ import annotations

import pytest
from rclpy.context import Context
from rclpy.parameter import Parameter

from ros_gz_bridge_py.app.settings import (
    TRANSPORT_IMPLEMENTATION_ENV,
    check_transport_implementation,
    declare_image_bridge_parameters,
    declare_parameter_bridge_parameters,
)
from ros_gz_bridge_py.errors import ConfigError
from tests.unit.app.test_settings import make_node


@pytest.mark.ros
@pytest.mark.parametrize(("value", "seconds"), [(10, 10.0), (2.5, 2.5), (1, 1.0)])
def test_service_timeout_takes_an_integer_or_a_decimal_number(
    ros_context: Context, value: float, seconds: float
) -> None:
    node = make_node(ros_context, [Parameter("service_timeout", value=value)])
    try:
        timeout = declare_parameter_bridge_parameters(node, {}).service_timeout
    finally:
        node.destroy_node()
    assert (timeout, type(timeout)) == (seconds, float)


@pytest.mark.ros
@pytest.mark.parametrize("value", [-1, 0, -0.5, 0.0, "abc", True])
def test_service_timeout_refuses_what_is_not_a_time_to_wait(
    ros_context: Context, value: object
) -> None:
    node = make_node(ros_context, [Parameter("service_timeout", value=value)])
    try:
        with pytest.raises(ConfigError) as raised:
            declare_parameter_bridge_parameters(node, {})
    finally:
        node.destroy_node()
    assert str(raised.value) == (
        f"parameter service_timeout must be a number of seconds > 0, such as 5 or 2.5, "
        f"got {value!r}"
    )


@pytest.mark.ros
@pytest.mark.parametrize("value", [0, -5])
def test_a_heartbeat_below_one_millisecond_is_refused_by_both_executables(
    ros_context: Context, value: int
) -> None:
    for declare in (declare_parameter_bridge_parameters, declare_image_bridge_parameters):
        node = make_node(ros_context, [Parameter("subscription_heartbeat", value=value)])
        try:
            with pytest.raises(ConfigError) as raised:
                declare(node, {})
        finally:
            node.destroy_node()
        assert str(raised.value) == (
            f"parameter subscription_heartbeat is {value}; it must be an integer >= 1 "
            "(milliseconds between lazy re-checks; default 1000)"
        )


@pytest.mark.ros
def test_a_heartbeat_of_one_millisecond_is_taken(ros_context: Context) -> None:
    node = make_node(ros_context, [Parameter("subscription_heartbeat", value=1)])
    try:
        params = declare_parameter_bridge_parameters(node, {})
    finally:
        node.destroy_node()
    assert params.shared.subscription_heartbeat == 1


@pytest.mark.parametrize(
    ("parameter", "env"),
    [("", {}), ("zenoh", {}), ("ZeroMQ", {}), ("", {TRANSPORT_IMPLEMENTATION_ENV: "Zenoh"})],
)
def test_known_transport_implementations_pass(parameter: str, env: dict[str, str]) -> None:
    check_transport_implementation(parameter, env)


def test_the_parameter_decides_before_the_variable() -> None:
    check_transport_implementation("zenoh", {TRANSPORT_IMPLEMENTATION_ENV: "foo"})
    with pytest.raises(ConfigError) as raised:
        check_transport_implementation("foo", {TRANSPORT_IMPLEMENTATION_ENV: "zenoh"})
    assert str(raised.value) == (
        "parameter gz_transport_implementation is 'foo', not a Gazebo Transport implementation; "
        "use one of zenoh, zeromq, or leave it out to follow "
        f"{TRANSPORT_IMPLEMENTATION_ENV}"
    )


def test_an_unknown_variable_value_is_named() -> None:
    with pytest.raises(ConfigError) as raised:
        check_transport_implementation("", {TRANSPORT_IMPLEMENTATION_ENV: "foo"})
    assert str(raised.value) == (
        f"{TRANSPORT_IMPLEMENTATION_ENV} is 'foo', not a Gazebo Transport implementation; "
        "use one of zenoh, zeromq, or unset it (zeromq)"
    )


@pytest.mark.parametrize("where", ["parameter", "variable"])
def test_the_tests_in_process_backend_is_refused(where: str) -> None:
    """``memory`` reaches no Gazebo: a bridge on it ran and carried nothing, without a word."""
    parameter, env = (
        ("memory", {}) if where == "parameter" else ("", {TRANSPORT_IMPLEMENTATION_ENV: "memory"})
    )
    with pytest.raises(ConfigError, match="'memory', not a Gazebo Transport implementation"):
        check_transport_implementation(parameter, env)

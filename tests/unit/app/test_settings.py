"""The one reader of the executables' settings: every switch, the node parameters, the options."""

from __future__ import annotations

import dataclasses
import signal
import uuid
from collections.abc import Callable, Sequence
from typing import Any

import pytest
import rclpy
from rclpy.context import Context
from rclpy.parameter import Parameter

from ros_gz_bridge_py.app.settings import (
    BULK_NICE_ENV,
    BULK_PATH_ENV,
    CDR_WRITE_ENV,
    DDS_EVENT_BATCH_ENV,
    EXECUTOR_ENV,
    FASTDDS_PROFILE_ENV,
    LIGHT_READ_ENV,
    MESSAGE_PATH_SWITCHES,
    NATIVE_ENV,
    ONE_CPU_ENV,
    READ_AT_START,
    SERIALIZED_PUBLISH_ENV,
    ImageBridgeParameters,
    ParameterBridgeParameters,
    SharedParameters,
    Switches,
    checked_max_queued_bytes,
    checked_max_rate,
    declare_image_bridge_parameters,
    declare_parameter_bridge_parameters,
    read_switches,
)
from ros_gz_bridge_py.core.bridge import BridgeOptions
from ros_gz_bridge_py.core.options import BULK_THREAD_NICE
from ros_gz_bridge_py.errors import ConfigError
from ros_gz_bridge_py.ros.stop_signal import StopSignal
from ros_gz_bridge_py.transport import NodeOptions
from ros_gz_bridge_py.transport.delivery import MAX_QUEUED_BYTES

#: Each on/off switch and the field it sets.
OFF_SWITCHES = {
    FASTDDS_PROFILE_ENV: "fastdds_profile",
    BULK_PATH_ENV: "bulk_path",
    LIGHT_READ_ENV: "light_read",
    CDR_WRITE_ENV: "cdr_write",
    DDS_EVENT_BATCH_ENV: "dds_event_batch",
    NATIVE_ENV: "native",
    ONE_CPU_ENV: "one_cpu",
}
#: Each choice switch, the value that chooses, and the field it sets False.
CHOICES = {
    EXECUTOR_ENV: ("single", "events_executor"),
    SERIALIZED_PUBLISH_ENV: ("rclpy", "rcl_serialized_publish"),
}


def switched(field: str) -> Switches:
    """The defaults with ``field`` False."""
    changes: dict[str, Any] = {field: False}
    return dataclasses.replace(Switches(), **changes)


def test_nothing_set_is_the_fast_defaults() -> None:
    assert read_switches({}) == Switches()
    assert read_switches({}) == Switches(
        events_executor=True,
        fastdds_profile=True,
        bulk_path=True,
        rcl_serialized_publish=True,
        bulk_nice=BULK_THREAD_NICE,
        light_read=True,
        cdr_write=True,
        dds_event_batch=True,
        one_cpu=True,
        warnings=(),
    )


def test_reads_the_process_environment_by_default(monkeypatch: pytest.MonkeyPatch) -> None:
    for name in [*OFF_SWITCHES, *CHOICES, BULK_NICE_ENV]:
        monkeypatch.delenv(name, raising=False)
    monkeypatch.setenv(BULK_PATH_ENV, "off")
    monkeypatch.setenv(BULK_NICE_ENV, "3")
    assert read_switches() == Switches(bulk_path=False, bulk_nice=3)


@pytest.mark.parametrize("name", list(OFF_SWITCHES))
@pytest.mark.parametrize("value", ["off", "OFF", " off ", "0", "false", "False", "no"])
def test_each_switch_turns_off(name: str, value: str) -> None:
    assert read_switches({name: value}) == switched(OFF_SWITCHES[name])


@pytest.mark.parametrize("name", list(OFF_SWITCHES))
@pytest.mark.parametrize("value", ["", "on", "1", "true", "yes", "offf", "single"])
def test_other_values_leave_a_switch_on(name: str, value: str) -> None:
    assert read_switches({name: value}) == Switches()


@pytest.mark.parametrize("name", list(CHOICES))
@pytest.mark.parametrize(
    "spell", [str.lower, str.upper, lambda v: f" {v.title()} "], ids=["lower", "upper", "spaced"]
)
def test_each_choice_takes_its_value_in_any_case(name: str, spell: Callable[[str], str]) -> None:
    value, field = CHOICES[name]
    assert read_switches({name: spell(value)}) == switched(field)


@pytest.mark.parametrize("name", list(CHOICES))
@pytest.mark.parametrize("value", ["", "events", "off", "ctypes", "multi"])
def test_other_values_leave_a_choice_at_its_default(name: str, value: str) -> None:
    assert read_switches({name: value}) == Switches()


@pytest.mark.parametrize(
    ("value", "nice"), [("", 10), ("  ", 10), ("0", 0), (" 5 ", 5), ("-3", -3)]
)
def test_bulk_nice_integers(value: str, nice: int) -> None:
    assert read_switches({BULK_NICE_ENV: value}) == Switches(bulk_nice=nice)


@pytest.mark.parametrize("value", ["low", "1.5", "ten", "5x"])
def test_bulk_nice_that_is_not_an_integer_is_named_with_its_fallback(value: str) -> None:
    switches = read_switches({BULK_NICE_ENV: value})
    assert switches.bulk_nice == BULK_THREAD_NICE
    assert switches.warnings == (
        f"ROS_GZ_BRIDGE_BULK_NICE={value!r} is not an integer; using 10 "
        "(set a whole number, 0 to keep image threads at normal priority)",
    )


def test_every_switch_at_once() -> None:
    env = {
        EXECUTOR_ENV: "single",
        FASTDDS_PROFILE_ENV: "no",
        BULK_PATH_ENV: "0",
        SERIALIZED_PUBLISH_ENV: "rclpy",
        BULK_NICE_ENV: "0",
        LIGHT_READ_ENV: "false",
        CDR_WRITE_ENV: "off",
        DDS_EVENT_BATCH_ENV: "No",
        ONE_CPU_ENV: "OFF",
    }
    assert read_switches(env) == Switches(
        events_executor=False,
        fastdds_profile=False,
        bulk_path=False,
        rcl_serialized_publish=False,
        bulk_nice=0,
        light_read=False,
        cdr_write=False,
        dds_event_batch=False,
        one_cpu=False,
    )


def test_bridge_options_from_parameters_and_switches() -> None:
    shared = SharedParameters(
        lazy=True,
        subscription_heartbeat=250,
        override_timestamps_with_wall_time=True,
        override_frame_id="cam",
        gz_version="GARDEN",
    )
    switches = Switches(bulk_path=False, rcl_serialized_publish=False, bulk_nice=2, cdr_write=False)
    options = shared.bridge_options(
        switches, gz_version="garden", service_timeout=1.5, max_queued_bytes=5_000_000
    )
    assert options == BridgeOptions(
        lazy=True,
        heartbeat=0.25,
        override_timestamps_with_wall_time=True,
        override_frame_id="cam",
        service_timeout=1.5,
        bulk_path=False,
        rcl_serialized_publish=False,
        bulk_nice=2,
        light_read=True,
        cdr_write=False,
        gz_version="garden",
        max_queued_bytes=5_000_000,
    )


@pytest.mark.parametrize(("value", "implementation"), [("", None), ("zenoh", "zenoh")])
def test_gz_node_options(value: str, implementation: str | None) -> None:
    shared = SharedParameters(gz_transport_implementation=value)
    stop = StopSignal()
    options = shared.gz_node_options(stop)
    assert options.stop_requested is not None
    assert dataclasses.replace(options, stop_requested=None) == NodeOptions(
        implementation=implementation
    )
    assert options.stop_requested() is False  # asks the executable's stop signal
    stop._request(signal.SIGINT, None)
    assert options.stop_requested() is True


# The node parameters, declared on a real rclpy node.


def make_node(context: Context, overrides: Sequence[Parameter] = ()) -> Any:
    return rclpy.create_node(
        f"settings_{uuid.uuid4().hex[:8]}", context=context, parameter_overrides=list(overrides)
    )


@pytest.mark.ros
def test_parameter_bridge_defaults(ros_context: Context) -> None:
    node = make_node(ros_context)
    try:
        params = declare_parameter_bridge_parameters(node, {})
    finally:
        node.destroy_node()
    assert params == ParameterBridgeParameters(
        SharedParameters(
            config_file="",
            lazy=False,
            subscription_heartbeat=1000,
            override_timestamps_with_wall_time=False,
            override_frame_id="",
            gz_transport_implementation="",
            gz_version="",
            expand_gz_topic_names=False,
            max_rate=0.0,
            status_period=0.0,
        ),
        service_timeout=5.0,
        bridge_names=(),
        auto_bridge=False,
        auto_bridge_allow=(),
        auto_bridge_deny=(),
        placeholders=(),
    )


@pytest.mark.ros
def test_every_parameter_has_a_value_so_tools_can_read_them_all(ros_context: Context) -> None:
    """The list parameters were declared without a value, and one such parameter emptied
    every answer of the node's get_parameters service: ``ros2 param dump`` printed nothing."""
    node = make_node(ros_context)
    try:
        declare_parameter_bridge_parameters(node, {})
        names = sorted(node.get_parameters_by_prefix(""))
        values = {parameter.name: parameter.value for parameter in node.get_parameters(names)}
    finally:
        node.destroy_node()
    assert {"bridge_names", "auto_bridge_allow", "auto_bridge_deny", "placeholders"} <= set(values)
    assert values["bridge_names"] == []


@pytest.mark.ros
def test_parameter_bridge_values(ros_context: Context) -> None:
    node = make_node(
        ros_context,
        [
            Parameter("config_file", value="/b.yaml"),
            Parameter("lazy", value=True),
            Parameter("subscription_heartbeat", value=200),
            Parameter("override_timestamps_with_wall_time", value=True),
            Parameter("override_frame_id", value="base"),
            Parameter("gz_transport_implementation", value="zenoh"),
            Parameter("gz_version", value="fortress"),
            Parameter("expand_gz_topic_names", value=True),
            Parameter("service_timeout", value=0.5),
            Parameter("bridge_names", value=["a", "b"]),
            Parameter("status_period", value=2),
            Parameter("max_rate", value=10),
            Parameter("max_queued_bytes", value=8_000_000),
            Parameter("auto_bridge", value=True),
            Parameter("auto_bridge_allow", value=["^/model/"]),
            Parameter("auto_bridge_deny", value=["camera", "lidar"]),
            Parameter("placeholders", value=["robot=r1,r2"]),
        ],
    )
    try:
        params = declare_parameter_bridge_parameters(node, {"GZ_VERSION": "garden"})
    finally:
        node.destroy_node()
    assert params == ParameterBridgeParameters(
        SharedParameters(
            "/b.yaml", True, 200, True, "base", "zenoh", "fortress", True, 10, 8_000_000, 2
        ),
        service_timeout=0.5,
        bridge_names=("a", "b"),
        auto_bridge=True,
        auto_bridge_allow=("^/model/",),
        auto_bridge_deny=("camera", "lidar"),
        placeholders=("robot=r1,r2",),
    )


@pytest.mark.parametrize(
    ("value", "expected"),
    [(0.0, (0.0, "")), (10, (10.0, "")), ("2.5", (2.5, "")), (-1, None), ("fast", None)],
)
def test_max_rate_parameter_is_checked(value: object, expected: tuple[float, str] | None) -> None:
    rate, problem = checked_max_rate(SharedParameters(max_rate=value))
    if expected is None:
        assert rate == 0.0
        assert "max_rate must be a number of messages per second >= 0" in problem
        assert "no limit is applied" in problem
    else:
        assert (rate, problem) == expected


@pytest.mark.parametrize("value", [0, -1])
def test_a_queue_of_no_bytes_is_reported_and_the_default_used(value: int) -> None:
    size, problem = checked_max_queued_bytes(SharedParameters(max_queued_bytes=value))
    assert size == MAX_QUEUED_BYTES
    assert f"parameter max_queued_bytes is {value}; it must be at least 1" in problem
    assert checked_max_queued_bytes(SharedParameters(max_queued_bytes=1)) == (1, "")


@pytest.mark.ros
def test_status_period_takes_any_type(ros_context: Context) -> None:
    """Checked and reported by start_diagnostics, not refused at declaration."""
    node = make_node(ros_context, [Parameter("status_period", value="often")])
    try:
        assert declare_parameter_bridge_parameters(node, {}).shared.status_period == "often"
    finally:
        node.destroy_node()


@pytest.mark.ros
@pytest.mark.parametrize("name", ["config_file", "lazy", "subscription_heartbeat", "max_rate"])
def test_a_parameter_set_at_run_time_is_refused_with_the_reason(
    ros_context: Context, name: str
) -> None:
    """It was accepted (successful=True) and ignored: every one is read once, at start."""
    given = Parameter("config_file", value="first.yaml")
    node = make_node(ros_context, [given])
    try:
        declare_parameter_bridge_parameters(node, {})
        before = node.get_parameter(name).value
        (result,) = node.set_parameters([Parameter(name, value="other.yaml")])
        assert not result.successful
        assert result.reason == f"Trying to set a read-only parameter: {name}."
        assert node.get_parameter(name).value == before
        assert node.describe_parameter(name).description == READ_AT_START
        assert node.get_parameter("config_file").value == "first.yaml"
    finally:
        node.destroy_node()


@pytest.mark.ros
def test_image_bridge_defaults_share_the_parameter_bridge_pieces(ros_context: Context) -> None:
    node = make_node(ros_context)
    try:
        params = declare_image_bridge_parameters(node, {"GZ_VERSION": "garden"})
    finally:
        node.destroy_node()
    assert params == ImageBridgeParameters(
        SharedParameters(gz_version="garden"),
        qos="default",
        camera_info=False,
        gz_type="gz.msgs.Image",
    )


@pytest.mark.ros
def test_image_bridge_values(ros_context: Context) -> None:
    node = make_node(
        ros_context,
        [
            Parameter("qos", value="sensor_data"),
            Parameter("camera_info", value=True),
            Parameter("gz_type", value="ignition.msgs.Image"),
            Parameter("lazy", value=True),
            Parameter("override_frame_id", value="optical"),
            Parameter("gz_version", value=""),
        ],
    )
    try:
        params = declare_image_bridge_parameters(node, {"GZ_VERSION": "garden"})
    finally:
        node.destroy_node()
    assert params == ImageBridgeParameters(
        SharedParameters(lazy=True, override_frame_id="optical", gz_version=""),
        qos="sensor_data",
        camera_info=True,
        gz_type="ignition.msgs.Image",
    )


@pytest.mark.ros
def test_gz_version_defaults_to_the_process_environment(
    ros_context: Context, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setenv("GZ_VERSION", "harmonic")
    node = make_node(ros_context)
    try:
        assert declare_image_bridge_parameters(node).shared.gz_version == "harmonic"
    finally:
        node.destroy_node()


def test_every_message_path_switch_is_a_bridge_option() -> None:
    """The switches handed to the bridge under the same names exist on both sides."""
    option_fields = {f.name for f in dataclasses.fields(BridgeOptions)}
    switch_fields = {f.name for f in dataclasses.fields(Switches)}
    assert set(MESSAGE_PATH_SWITCHES) <= option_fields & switch_fields


@pytest.mark.ros
@pytest.mark.parametrize(
    ("name", "value", "wanted"),
    [
        ("expand_gz_topic_names", "maybe", "true or false"),
        ("subscription_heartbeat", "often", "an integer"),
        ("config_file", 5, "a string"),
        ("bridge_names", "robot", "a list of strings, such as ['a', 'b']"),
        ("placeholders", [1, 2], "a list of strings, such as ['a', 'b']"),
    ],
)
def test_a_parameter_of_the_wrong_type_is_named_with_the_fix(
    ros_context: Context, name: str, value: object, wanted: str
) -> None:
    node = make_node(ros_context, [Parameter(name, value=value)])
    try:
        with pytest.raises(ConfigError) as raised:
            declare_parameter_bridge_parameters(node, {})
    finally:
        node.destroy_node()
    text = str(raised.value)
    assert text.startswith(f"parameter {name} has the wrong type (Trying to set parameter ")
    assert f"'{value}'" in text
    assert text.endswith(f"); give it as {wanted}, or leave it out")

"""The executables' node parameters, declared in one place, and the options they make."""

from __future__ import annotations

import uuid
from collections.abc import Iterator, Sequence
from typing import Any

import pytest
import rclpy
from rclpy.context import Context
from rclpy.parameter import Parameter

from ros_gz_bridge_py.app.settings import (
    ImageBridgeParameters,
    ParameterBridgeParameters,
    SharedParameters,
    declare_image_bridge_parameters,
    declare_parameter_bridge_parameters,
)
from ros_gz_bridge_py.core.bridge import BridgeOptions
from ros_gz_bridge_py.transport import NodeOptions


def test_bridge_options_from_parameters() -> None:
    shared = SharedParameters(
        lazy=True,
        subscription_heartbeat=250,
        override_timestamps_with_wall_time=True,
        override_frame_id="cam",
        gz_version="GARDEN",
    )
    options = shared.bridge_options(gz_version="garden", service_timeout=1.5)
    assert options == BridgeOptions(
        lazy=True,
        heartbeat=0.25,
        override_timestamps_with_wall_time=True,
        override_frame_id="cam",
        service_timeout=1.5,
        gz_version="garden",
    )


@pytest.mark.parametrize(("milliseconds", "seconds"), [(1000, 1.0), (0, 0.001), (-5, 0.001)])
def test_heartbeat_is_at_least_one_millisecond(milliseconds: int, seconds: float) -> None:
    shared = SharedParameters(subscription_heartbeat=milliseconds)
    assert shared.bridge_options(gz_version="").heartbeat == seconds


@pytest.mark.parametrize(("value", "implementation"), [("", None), ("zenoh", "zenoh")])
def test_gz_node_options(value: str, implementation: str | None) -> None:
    shared = SharedParameters(gz_transport_implementation=value)
    assert shared.gz_node_options() == NodeOptions(implementation=implementation)


# The node parameters, declared on a real rclpy node.


@pytest.fixture
def context() -> Iterator[Context]:
    context = Context()
    rclpy.init(context=context)
    try:
        yield context
    finally:
        rclpy.try_shutdown(context=context)


def make_node(context: Context, overrides: Sequence[Parameter] = ()) -> Any:
    return rclpy.create_node(
        f"settings_{uuid.uuid4().hex[:8]}", context=context, parameter_overrides=list(overrides)
    )


@pytest.mark.ros
def test_parameter_bridge_defaults(context: Context) -> None:
    node = make_node(context)
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
        ),
        expand_gz_topic_names=False,
        service_timeout=5.0,
        bridge_names=(),
        status_period=0.0,
    )


@pytest.mark.ros
def test_parameter_bridge_values(context: Context) -> None:
    node = make_node(
        context,
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
        ],
    )
    try:
        params = declare_parameter_bridge_parameters(node, {"GZ_VERSION": "garden"})
    finally:
        node.destroy_node()
    assert params == ParameterBridgeParameters(
        SharedParameters("/b.yaml", True, 200, True, "base", "zenoh", "fortress"),
        expand_gz_topic_names=True,
        service_timeout=0.5,
        bridge_names=("a", "b"),
        status_period=2,
    )


@pytest.mark.ros
def test_status_period_takes_any_type(context: Context) -> None:
    """Checked and reported by start_diagnostics, not refused at declaration."""
    node = make_node(context, [Parameter("status_period", value="often")])
    try:
        assert declare_parameter_bridge_parameters(node, {}).status_period == "often"
    finally:
        node.destroy_node()


@pytest.mark.ros
def test_image_bridge_defaults_share_the_parameter_bridge_pieces(context: Context) -> None:
    node = make_node(context)
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
def test_image_bridge_values(context: Context) -> None:
    node = make_node(
        context,
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
    context: Context, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setenv("GZ_VERSION", "harmonic")
    node = make_node(context)
    try:
        assert declare_image_bridge_parameters(node).shared.gz_version == "harmonic"
    finally:
        node.destroy_node()

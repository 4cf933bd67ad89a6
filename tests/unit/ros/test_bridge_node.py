"""BridgeNode: rclpy's node whose parameter and type description services start when the bridge
says so, and are then what rclpy's own node offers (real rclpy nodes, in process; the bridge
executables' use of it is in tests/bridge/test_start_up.py)."""

from __future__ import annotations

import uuid
from collections.abc import Sequence
from typing import Any

import pytest
import rclpy
from rcl_interfaces.srv import ListParameters
from rclpy.context import Context
from rclpy.executors import SingleThreadedExecutor
from rclpy.parameter import Parameter

from ros_gz_bridge_py.ros.bridge_node import BridgeNode
from tests.rclpy_services import PARAMETER_SERVICES

pytestmark = pytest.mark.ros


def unique(stem: str) -> str:
    return f"{stem}_{uuid.uuid4().hex[:8]}"


def own_services(node: Any) -> set[str]:
    """The names (after the node's name) of the services the node offers."""
    prefix = f"{node.get_name()}/"
    return {service.srv_name.removeprefix(prefix) for service in node.services}


def test_the_services_wait_for_start_services_then_are_rclpys(ros_context: Context) -> None:
    plain = rclpy.create_node(unique("plain"), context=ros_context)
    node = BridgeNode(unique("held"), context=ros_context)
    try:
        assert own_services(node) == set()
        assert node.get_parameter("start_type_description_service").value is True
        node.start_services()
        node.start_services()  # a second call adds nothing
        assert own_services(node) == own_services(plain) == set(PARAMETER_SERVICES)
        assert len(list(node.services)) == len(PARAMETER_SERVICES)
    finally:
        node.destroy_node()
        plain.destroy_node()


def test_the_users_start_type_description_service_false_is_kept(ros_context: Context) -> None:
    node = BridgeNode(
        unique("no_types"),
        context=ros_context,
        parameter_overrides=[Parameter("start_type_description_service", value=False)],
    )
    try:
        node.start_services()
        assert own_services(node) == set(PARAMETER_SERVICES) - {"get_type_description"}
        assert node.get_parameter("start_type_description_service").value is False
    finally:
        node.destroy_node()


def call(context: Context, nodes: Sequence[Any], client: Any, request: Any) -> Any:
    executor = SingleThreadedExecutor(context=context)
    for node in nodes:
        executor.add_node(node)
    try:
        assert client.wait_for_service(timeout_sec=10.0)
        future = client.call_async(request)
        executor.spin_until_future_complete(future, timeout_sec=10.0)
        assert future.done()
        return future.result()
    finally:
        executor.shutdown()


def test_started_parameter_services_answer_with_the_nodes_parameters(ros_context: Context) -> None:
    node = BridgeNode(unique("answers"), context=ros_context)
    asker = rclpy.create_node(unique("asker"), context=ros_context)
    try:
        node.declare_parameter("config_file", "bridge.yaml")
        node.start_services()
        client = asker.create_client(ListParameters, f"/{node.get_name()}/list_parameters")
        names = call(ros_context, [node, asker], client, ListParameters.Request()).result.names
        assert {"config_file", "start_type_description_service", "use_sim_time"} <= set(names)
    finally:
        asker.destroy_node()
        node.destroy_node()

"""Test-session set-up shared by every test: keep all traffic on this host.

The environment is set at import time, before any test imports rclpy or opens a Gazebo
Transport node, and is inherited by every subprocess a test starts (real ign tools, rclpy
processes). It mirrors ``../shared/tools/loopback-env`` with a domain and partition unique
to this pytest process, so parallel runs never meet.
"""

from __future__ import annotations

import os
import uuid
from collections.abc import Iterator
from typing import Any

import pytest

_PARTITION = f"rgbp-test-{os.getpid()}-{uuid.uuid4().hex[:6]}"

os.environ.update(
    {
        "ROS_AUTOMATIC_DISCOVERY_RANGE": "LOCALHOST",
        "ROS_LOCALHOST_ONLY": "1",
        "GZ_IP": "127.0.0.1",
        "IGN_IP": "127.0.0.1",
        "ROS_DOMAIN_ID": str(os.getpid() % 200 + 1),
        "GZ_PARTITION": _PARTITION,
        "IGN_PARTITION": _PARTITION,
    }
)
os.environ.pop("GZ_RELAY", None)
os.environ.pop("IGN_RELAY", None)
os.environ.pop("GZ_TRANSPORT_IMPLEMENTATION", None)


@pytest.fixture
def ros_context() -> Iterator[Any]:
    """An rclpy context of the test's own (the environment above applies), shut down after it.
    rclpy is imported here, so only the tests that ask for a context load it."""
    import rclpy  # noqa: PLC0415
    from rclpy.context import Context  # noqa: PLC0415

    context = Context()
    rclpy.init(context=context)
    try:
        yield context
    finally:
        rclpy.try_shutdown(context=context)


@pytest.fixture
def network() -> Iterator[Any]:
    """An in-memory Gazebo network of the test's own; its nodes are closed after it. Imported
    here, as rclpy above, once the environment is set."""
    from ros_gz_bridge_py.transport.memory.network import MemoryNetwork  # noqa: PLC0415

    network = MemoryNetwork()
    yield network
    for node in list(network.nodes):
        node.close()

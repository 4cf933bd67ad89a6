"""The built extension, and a publisher for the pumps, for the native tests that use them."""

from __future__ import annotations

from collections.abc import Iterator
from typing import Any

import pytest

from ros_gz_bridge_py.native import extension


@pytest.fixture(scope="module")
def native() -> Any:
    module = extension()
    if module is None:
        pytest.skip("the native extension is not built (test_native_path.py requires it in CI)")
    return module


@pytest.fixture
def publisher(ros_context: Any, request: pytest.FixtureRequest) -> Iterator[Any]:
    """An rclpy std_msgs/String publisher for the C pumps to publish on, its node and topic
    named after the test module (``test_pump_loop``: ``pump_loop_test``)."""
    from rclpy.node import Node  # noqa: PLC0415 - rclpy only for the tests that ask
    from std_msgs.msg import String  # noqa: PLC0415

    name = request.module.__name__.rpartition(".")[2].removeprefix("test_") + "_test"
    node = Node(name, context=ros_context)
    try:
        yield node.create_publisher(String, f"/{name}", 10)
    finally:
        node.destroy_node()

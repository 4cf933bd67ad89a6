"""Console entry points: ``parameter_bridge``, ``bridge_node``, ``image_bridge`` and
``bridge_types``."""

from __future__ import annotations

import sys

from ros_gz_bridge_py.app.rclpy_check import rclpy_problem
from ros_gz_bridge_py.app.startup import one_blas_thread, pause_collector
from ros_gz_bridge_py.ros.stop_signal import StopSignal


def _exit_without_rclpy(program: str) -> None:
    """Stop with one line that says what is needed, before an import of rclpy would fail."""
    problem = rclpy_problem()
    if problem is not None:
        print(f"{program}: {problem}", file=sys.stderr)
        sys.exit(1)


def parameter_bridge_main() -> None:
    one_blas_thread()
    pause_collector()
    _exit_without_rclpy("parameter_bridge")
    with StopSignal() as stop:
        from ros_gz_bridge_py.app import parameter_bridge  # noqa: PLC0415 - imports rclpy

        sys.exit(parameter_bridge.main(stop=stop))


def bridge_node_main() -> None:
    one_blas_thread()
    pause_collector()
    _exit_without_rclpy("bridge_node")
    with StopSignal() as stop:
        from ros_gz_bridge_py.app import bridge_node  # noqa: PLC0415 - imports rclpy

        sys.exit(bridge_node.main(stop=stop))


def bridge_types_main() -> None:
    from ros_gz_bridge_py.app import bridge_types  # noqa: PLC0415

    sys.exit(bridge_types.main())


def image_bridge_main() -> None:
    one_blas_thread()
    pause_collector()
    _exit_without_rclpy("image_bridge")
    with StopSignal() as stop:
        from ros_gz_bridge_py.app import image_bridge  # noqa: PLC0415 - imports rclpy

        sys.exit(image_bridge.main(stop=stop))

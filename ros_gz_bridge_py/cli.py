"""Console entry points: ``parameter_bridge``, ``bridge_node``, ``image_bridge`` and
``bridge_types``."""

from __future__ import annotations

import os
import sys
from collections.abc import Callable
from typing import NoReturn

from ros_gz_bridge_py.app.rclpy_check import rclpy_problem
from ros_gz_bridge_py.app.startup import one_blas_thread, pause_collector
from ros_gz_bridge_py.ros.stop_signal import StopSignal


def _exit_without_rclpy(program: str) -> None:
    """Stop with one line that says what is needed, before an import of rclpy would fail."""
    problem = rclpy_problem()
    if problem is not None:
        print(f"{program}: {problem}", file=sys.stderr)
        sys.exit(1)


def _exit_with(main: Callable[[], int]) -> NoReturn:
    """Exit with ``main()``'s code. A reader that closed the pipe early (``--help | head -1``)
    ends the output: no traceback."""
    try:
        code = main()
        sys.stdout.flush()
    except BrokenPipeError:
        # Python flushes stdout once more at exit; /dev/null takes what is left.
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        code = 1
    sys.exit(code)


def parameter_bridge_main() -> None:
    one_blas_thread()
    pause_collector()
    _exit_without_rclpy("parameter_bridge")
    with StopSignal() as stop:
        from ros_gz_bridge_py.app import parameter_bridge  # noqa: PLC0415 - imports rclpy

        _exit_with(lambda: parameter_bridge.main(stop=stop))


def bridge_node_main() -> None:
    one_blas_thread()
    pause_collector()
    _exit_without_rclpy("bridge_node")
    with StopSignal() as stop:
        from ros_gz_bridge_py.app import bridge_node  # noqa: PLC0415 - imports rclpy

        _exit_with(lambda: bridge_node.main(stop=stop))


def bridge_types_main() -> None:
    _exit_without_rclpy("bridge_types")  # the pairs are built from ROS message classes
    from ros_gz_bridge_py.app import bridge_types  # noqa: PLC0415 - imports rclpy

    _exit_with(bridge_types.main)


def image_bridge_main() -> None:
    one_blas_thread()
    pause_collector()
    _exit_without_rclpy("image_bridge")
    with StopSignal() as stop:
        from ros_gz_bridge_py.app import image_bridge  # noqa: PLC0415 - imports rclpy

        _exit_with(lambda: image_bridge.main(stop=stop))

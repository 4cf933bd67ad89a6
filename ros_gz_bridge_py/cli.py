"""Console entry points: ``parameter_bridge``, ``image_bridge`` and ``bridge_types``."""

from __future__ import annotations

import sys


def parameter_bridge_main() -> None:
    from ros_gz_bridge_py import parameter_bridge  # noqa: PLC0415 - only this command needs rclpy

    sys.exit(parameter_bridge.main())


def bridge_types_main() -> None:
    from ros_gz_bridge_py import bridge_types  # noqa: PLC0415

    sys.exit(bridge_types.main())


def image_bridge_main() -> None:
    from ros_gz_bridge_py import image_bridge  # noqa: PLC0415 - only this command needs rclpy

    sys.exit(image_bridge.main())

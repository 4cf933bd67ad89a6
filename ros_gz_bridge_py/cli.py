"""Console entry points: ``parameter_bridge``, ``bridge_types`` (and ``image_bridge``)."""

from __future__ import annotations

import sys


def parameter_bridge_main() -> None:
    from ros_gz_bridge_py import parameter_bridge  # noqa: PLC0415 - only this command needs rclpy

    sys.exit(parameter_bridge.main())


def bridge_types_main() -> None:
    from ros_gz_bridge_py import bridge_types  # noqa: PLC0415

    sys.exit(bridge_types.main())

"""ROS <-> Gazebo message converters: one module per ROS package, one registry.

See :mod:`ros_gz_bridge_py.converters.registry`.
"""

from ros_gz_bridge_py.converters.registry import (
    Pair,
    Registry,
    ServicePair,
    build_registry,
    default_registry,
)

__all__ = [
    "Pair",
    "Registry",
    "ServicePair",
    "build_registry",
    "default_registry",
]

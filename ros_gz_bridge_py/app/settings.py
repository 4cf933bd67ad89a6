"""The node parameters of the executables, declared once for both, into frozen dataclasses.

``parameter_bridge`` and ``image_bridge`` declare the parameters they share
(:class:`SharedParameters`) here, with one name, type and default; ``GZ_VERSION`` is the default
of ``gz_version``. README: "Node parameters".
"""

from __future__ import annotations

import dataclasses
import os
from collections.abc import Collection, Mapping
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, TypeVar

from rcl_interfaces.msg import ParameterDescriptor
from rclpy.parameter import Parameter

from ros_gz_bridge_py.config.gz_version import GZ_VERSION_ENV
from ros_gz_bridge_py.core.bridge import BridgeOptions
from ros_gz_bridge_py.core.services import DEFAULT_TIMEOUT
from ros_gz_bridge_py.transport import NodeOptions

if TYPE_CHECKING:
    from _typeshed import DataclassInstance


@dataclass(frozen=True)
class SharedParameters:
    """The node parameters both executables declare (the C++ bridge's, and ours)."""

    config_file: str = ""
    lazy: bool = False
    #: Milliseconds between two lazy re-checks.
    subscription_heartbeat: int = 1000
    override_timestamps_with_wall_time: bool = False
    override_frame_id: str = ""
    #: Ours: "zeromq" or "zenoh"; empty = GZ_TRANSPORT_IMPLEMENTATION, as gz-transport does.
    gz_transport_implementation: str = ""
    #: Ours: the simulator's Gazebo line, when it must be said (only "garden" matters);
    #: declared with ``GZ_VERSION`` as its default.
    gz_version: str = ""

    def gz_node_options(self) -> NodeOptions:
        return NodeOptions(implementation=self.gz_transport_implementation or None)

    def bridge_options(
        self, *, gz_version: str, service_timeout: float = DEFAULT_TIMEOUT
    ) -> BridgeOptions:
        """The bridge's options: these parameters, and ``gz_version`` as checked by
        :func:`~ros_gz_bridge_py.config.gz_version.check_gz_version`."""
        return BridgeOptions(
            lazy=self.lazy,
            heartbeat=max(self.subscription_heartbeat, 1) / 1000.0,
            override_timestamps_with_wall_time=self.override_timestamps_with_wall_time,
            override_frame_id=self.override_frame_id,
            service_timeout=service_timeout,
            gz_version=gz_version,
        )


@dataclass(frozen=True)
class ParameterBridgeParameters:
    """``parameter_bridge``'s node parameters."""

    shared: SharedParameters
    expand_gz_topic_names: bool = False
    #: Ours: seconds a ROS service call waits for Gazebo before answering success=false.
    service_timeout: float = DEFAULT_TIMEOUT
    #: The ``bridges.<name>.*`` groups to read (a string array parameter with no default).
    bridge_names: tuple[str, ...] = ()
    #: Ours: seconds between two /diagnostics status messages (0 = none). Any type may be
    #: given; ``start_diagnostics`` takes an int or a float and reports anything else.
    status_period: object = 0.0


@dataclass(frozen=True)
class ImageBridgeParameters:
    """``image_bridge``'s node parameters: the shared ones and ros_gz_image's own."""

    shared: SharedParameters
    qos: str = "default"
    camera_info: bool = False
    gz_type: str = "gz.msgs.Image"


_Parameters = TypeVar("_Parameters", bound="DataclassInstance")


def _declare_fields(node: Any, defaults: _Parameters, skip: Collection[str]) -> _Parameters:
    """Declare a parameter per field of ``defaults`` but those in ``skip``, each defaulting to
    its value (which sets its type); ``defaults`` with the declared values."""
    values = {
        field.name: node.declare_parameter(field.name, getattr(defaults, field.name)).value
        for field in dataclasses.fields(defaults)
        if field.name not in skip
    }
    return dataclasses.replace(defaults, **values)


def declare_shared_parameters(node: Any, env: Mapping[str, str] | None = None) -> SharedParameters:
    """Declare the shared parameters on ``node``; ``gz_version`` defaults to ``GZ_VERSION`` of
    ``env`` (default: the process's environment)."""
    env = os.environ if env is None else env
    return _declare_fields(node, SharedParameters(gz_version=env.get(GZ_VERSION_ENV, "")), ())


def declare_parameter_bridge_parameters(
    node: Any, env: Mapping[str, str] | None = None
) -> ParameterBridgeParameters:
    """Declare ``parameter_bridge``'s parameters on ``node`` and return their values."""
    declared = _declare_fields(
        node,
        ParameterBridgeParameters(declare_shared_parameters(node, env)),
        ("shared", "bridge_names", "status_period"),
    )
    names = node.declare_parameter("bridge_names", Parameter.Type.STRING_ARRAY).value
    any_type = ParameterDescriptor(dynamic_typing=True)
    period = node.declare_parameter("status_period", declared.status_period, any_type).value
    return dataclasses.replace(declared, bridge_names=tuple(names or ()), status_period=period)


def declare_image_bridge_parameters(
    node: Any, env: Mapping[str, str] | None = None
) -> ImageBridgeParameters:
    """Declare ``image_bridge``'s parameters on ``node`` and return their values."""
    shared = declare_shared_parameters(node, env)
    return _declare_fields(node, ImageBridgeParameters(shared), ("shared",))

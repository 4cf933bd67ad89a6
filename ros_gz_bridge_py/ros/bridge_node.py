"""The bridge's rclpy node, whose own services start once its channels exist.

rclpy's node offers parameter services and ``~/get_type_description`` from its constructor.
Every service type of this ROS release carries a ``service_msgs/ServiceEventInfo``, whose module
imports numpy: about 0.05 s of a start-up that C++ does in 0.15 s (docs/environment.md §3).
Bridging a String needs neither, so :class:`BridgeNode` holds both back until
:meth:`BridgeNode.start_services`, which the apps call once the configured channels exist. The
services are the same, as is the ``start_type_description_service`` parameter (the user's value,
read when they start); they come a moment later.
"""

from __future__ import annotations

from typing import Any

from rclpy.node import Node
from rclpy.parameter import Parameter
from rclpy.parameter_service import ParameterService
from rclpy.type_description_service import (
    START_TYPE_DESCRIPTION_SERVICE_PARAM,
    TypeDescriptionService,
)


class BridgeNode(Node):  # type: ignore[misc]  # rclpy is Any under mypy (pyproject.toml)
    """A node whose parameter and type description services start with :meth:`start_services`."""

    def __init__(self, node_name: str, **kwargs: Any) -> None:
        self._holding_services = True
        super().__init__(node_name, start_parameter_services=False, **kwargs)
        self._holding_services = False
        self._services_started = False

    def get_parameter(self, name: str) -> Parameter:
        """The parameter; while the constructor runs, ``start_type_description_service`` reads
        false, so that rclpy's constructor does not start the service (it is read again, as the
        user set it, by :meth:`start_services`)."""
        if self._holding_services and name == START_TYPE_DESCRIPTION_SERVICE_PARAM:
            return Parameter(name, Parameter.Type.BOOL, False)
        return super().get_parameter(name)

    def start_services(self) -> None:
        """Start the parameter services, and ``~/get_type_description`` unless the
        ``start_type_description_service`` parameter is false; a second call does nothing."""
        if self._services_started:
            return
        self._services_started = True
        self._parameter_service = ParameterService(self)
        self._type_description_service = TypeDescriptionService(self)

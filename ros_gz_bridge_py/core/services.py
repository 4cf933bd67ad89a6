"""Service bridges: a ROS service whose requests are forwarded to a Gazebo service.

Service bridges live on the bridge's side node (``side_node.py``), spun by a multi-threaded
executor in its own thread: each call converts the request, waits (blocking that executor thread
only) for the Gazebo reply or the timeout, and returns exactly one response —
the converted reply, or ``success=False`` when Gazebo reports failure, does not answer in time,
or the request cannot be converted. The C++ bridge can answer twice, and never answers when
Gazebo is absent. Keeping calls off the main executor means a slow or absent Gazebo service never
delays topic traffic (the EventsExecutor also cannot run coroutine service callbacks).
"""

from __future__ import annotations

from typing import Any

from ros_gz_bridge_py.config import ServiceBridgeSpec
from ros_gz_bridge_py.converters.registry import ServicePair
from ros_gz_bridge_py.errors import ConfigError, ConversionError, TransportError
from ros_gz_bridge_py.msgs import message_class
from ros_gz_bridge_py.msgs.names import same_message
from ros_gz_bridge_py.ros.side_node import SideNode
from ros_gz_bridge_py.transport import GzNode

DEFAULT_TIMEOUT = 5.0


def resolve_gz_types(spec: ServiceBridgeSpec, pair: ServicePair) -> tuple[str, str]:
    """The Gazebo request/reply type strings to use on the wire for ``spec``.

    Omitted types take the pair's defaults. Given types must name the pair's types, in either
    spelling (``gz.msgs.X`` or, for Fortress, ``ignition.msgs.X``); the spelling is kept because
    Gazebo matches service types as exact strings.

    Raises:
        ConfigError: a given type is not the one this ROS service type converts to.
    """
    chosen = []
    for given, expected, what in (
        (spec.gz_req_type, pair.gz_req_type, "request"),
        (spec.gz_rep_type, pair.gz_rep_type, "reply"),
    ):
        if not given:
            chosen.append(expected)
        elif same_message(given, expected):
            chosen.append(given)
        else:
            msg = (
                f"service [{spec.service}] of type [{spec.ros_type}] needs Gazebo {what} type "
                f"[{expected}], not [{given}]; omit the Gazebo types to use the defaults"
            )
            raise ConfigError(msg, spec.source or None)
    return chosen[0], chosen[1]


class ServiceBridge:
    """One ROS service forwarded to one Gazebo service."""

    def __init__(
        self,
        host: SideNode,
        gz_node: GzNode,
        spec: ServiceBridgeSpec,
        pair: ServicePair,
        timeout: float = DEFAULT_TIMEOUT,
    ) -> None:
        self.spec = spec
        self.pair = pair
        self.timeout = timeout
        self.gz_req_type, self.gz_rep_type = resolve_gz_types(spec, pair)
        self._reply_class = message_class(self.gz_rep_type)
        self._ros_node = host.node
        self._gz_node = gz_node
        self._logger = host.node.get_logger()
        self.calls = 0
        self.failures = 0
        self._service = host.node.create_service(
            pair.ros_class, spec.service, self._on_request, callback_group=host.reentrant
        )
        self.service_name: str = self._service.srv_name

    def describe(self) -> str:
        return (
            f"ROS->GZ service [{self.service_name} ({self.spec.ros_type} -> "
            f"{self.gz_req_type}/{self.gz_rep_type})]"
        )

    def _on_request(self, request: Any, _response: Any) -> Any:
        self.calls += 1
        try:
            payload = self.pair.request_to_gz(request).SerializeToString()
        except ConversionError as err:
            return self._fail(f"request not converted: {err}")
        try:
            success, reply = self._gz_node.request(
                self.spec.service, payload, self.gz_req_type, self.gz_rep_type, self.timeout
            )
        except TimeoutError:
            return self._fail(f"no reply from Gazebo within {self.timeout:g} s")
        except TransportError as err:
            return self._fail(f"request failed: {err}")
        if not success:
            return self._fail("Gazebo reported failure")
        try:
            return self.pair.reply_to_ros(self._reply_class.FromString(reply))
        except Exception as err:
            return self._fail(f"reply not converted: {err}")

    def _fail(self, why: str) -> Any:
        self.failures += 1
        self._logger.warning(f"{self.describe()}: {why}")
        return self.pair.failure_to_ros()

    def close(self) -> None:
        if self._service is not None:
            self._ros_node.destroy_service(self._service)
            self._service = None

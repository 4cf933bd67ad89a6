"""The bridge: channels and service bridges on one rclpy node and one Gazebo Transport node.

Embedding::

    import rclpy
    from rclpy.node import Node
    from ros_gz_bridge_py import Bridge
    from ros_gz_bridge_py.config import Direction, TopicBridgeSpec

    rclpy.init()
    node = Node("my_node")
    bridge = Bridge(node)
    handle = bridge.add(TopicBridgeSpec("/chatter", "/chatter", "std_msgs/msg/String",
                                        "gz.msgs.StringMsg", Direction.GZ_TO_ROS))
    ...                      # spin the node with any executor
    bridge.remove(handle)    # bridges come and go at run time
    bridge.close()

The bridge creates a wall-clock (steady) timer on the node that re-evaluates lazy channels every
``heartbeat`` seconds, as the C++ bridge does with ``subscription_heartbeat``. Its settings are
the :class:`BridgeOptions` it is given; it reads no environment variable.
"""

from __future__ import annotations

import dataclasses
import threading
from collections.abc import Iterable
from dataclasses import dataclass, field
from typing import Any

from ros_gz_bridge_py.config import (
    BridgeSpec,
    Direction,
    ServiceBridgeSpec,
    TopicBridgeSpec,
)
from ros_gz_bridge_py.converters.registry import Registry, default_registry
from ros_gz_bridge_py.core.channel import Channel, ChannelContext
from ros_gz_bridge_py.core.explain import EXPLAIN_PERIOD, Explainer
from ros_gz_bridge_py.core.gz_to_ros import GzToRosChannel
from ros_gz_bridge_py.core.node_share import share_of
from ros_gz_bridge_py.core.options import BridgeOptions
from ros_gz_bridge_py.core.ros_to_gz import RosToGzChannel
from ros_gz_bridge_py.core.services import ServiceBridge
from ros_gz_bridge_py.core.spec_checks import (
    Key,
    checked_spec,
    refused_name_fix,
    service_key,
    topic_keys,
)
from ros_gz_bridge_py.errors import (
    RCL_SOURCE_LOCATION,
    BridgeError,
    ConfigError,
    UnsupportedTypeError,
)
from ros_gz_bridge_py.msgs.names import Spelling
from ros_gz_bridge_py.ros.quick_log import quick_logger
from ros_gz_bridge_py.ros.runtime import steady_clock
from ros_gz_bridge_py.ros.side_node import (
    SideNode,
    native_node_name,
    side_node_name,
    unspun_node,
)
from ros_gz_bridge_py.transport import GzNode, NodeOptions, create_gz_node

__all__ = ["Bridge", "BridgeHandle", "BridgeOptions"]


@dataclass
class BridgeHandle:
    """What one :meth:`Bridge.add` created: its channels (topic) or its service bridge."""

    spec: BridgeSpec
    channels: list[Channel] = field(default_factory=list)
    service: ServiceBridge | None = None


class Bridge:
    """Owns the bridges of one rclpy node; thread-safe ``add``/``remove``/``close``."""

    def __init__(
        self,
        ros_node: Any,
        *,
        gz_node: GzNode | None = None,
        options: BridgeOptions | None = None,
        registry: Registry | None = None,
        gz_options: NodeOptions | None = None,
    ) -> None:
        """Bridge on ``ros_node`` (an rclpy node the caller spins and, after :meth:`close`,
        destroys) and ``gz_node`` (None: one of its own, made from ``gz_options`` and closed
        with the bridge). The channels' ROS endpoints go on ``ros_node``: a lazy channel does
        not count that node's other endpoints. ``registry``: the pairs (None: every pair).
        Close the bridge before ``rclpy.shutdown()``."""
        self.options = options or BridgeOptions()
        self.ros_node = ros_node
        self.registry = registry or default_registry()
        self._owns_gz_node = gz_node is None
        if self.options.garden:
            gz_options = dataclasses.replace(
                gz_options or NodeOptions(), legacy_spelling=Spelling.GZ
            )
        self._share = share_of(ros_node)
        self._number = self._share.number()
        try:
            self.gz_node = gz_node if gz_node is not None else create_gz_node(gz_options)
        except BaseException:
            self._share.give_back(self._number)
            raise
        try:
            self._start(ros_node)
        except BaseException:  # a failed construction leaves nothing running
            self._share.give_back(self._number)
            if self._owns_gz_node:
                self.gz_node.close()
            raise

    def _start(self, ros_node: Any) -> None:
        """What :meth:`__init__` makes once the Gazebo node exists."""
        self._side: SideNode | None = None
        self._native: Any = None
        self._ctx = ChannelContext(
            ros_node=ros_node,
            gz_node=self.gz_node,
            side_node=lambda: self._side_node().node,
            native_node=self._native_node,
            own_nodes=frozenset(
                {
                    (ros_node.get_name(), ros_node.get_namespace()),
                    (side_node_name(ros_node, self._number), ros_node.get_namespace()),
                    (native_node_name(ros_node, self._number), ros_node.get_namespace()),
                }
            ),
            options=self.options,
        )
        self._logger = quick_logger(ros_node.get_logger())
        self._lock = threading.RLock()
        self._handles: list[BridgeHandle] = []
        self._closed = False
        steady = steady_clock()
        self._timer = ros_node.create_timer(self.options.heartbeat, self.heartbeat, clock=steady)
        self._explainer: Explainer | None = None
        #: What was said of each service bridge's providers (``_explain_services``).
        self._services_said: dict[tuple[int, str], str] = {}
        self._explain_timer: Any = None
        if self.options.explain:
            self._explainer = Explainer(
                self.gz_node,
                self.registry,
                self._ctx.own_nodes,
                self._logger.warning,
                note=self._logger.info,
                types_fixed_by=self.options.types_fixed_by,
                qos_setting=self.options.qos_setting,
            )
            self._explain_timer = ros_node.create_timer(EXPLAIN_PERIOD, self.explain, clock=steady)

    @property
    def own_nodes(self) -> frozenset[tuple[str, str]]:
        """(name, namespace) of the bridge's ROS nodes: its endpoints are not the graph's."""
        return self._ctx.own_nodes

    @property
    def handles(self) -> list[BridgeHandle]:
        """What every :meth:`add` still open created, in order (a copy)."""
        with self._lock:
            return list(self._handles)

    @property
    def channels(self) -> list[Channel]:
        """Every topic bridge's channels (one per direction); each has its ``stats``."""
        return [channel for handle in self.handles for channel in handle.channels]

    def carries_bulk(self) -> bool:
        """True when a channel takes the bulk path (images, point clouds)."""
        return any(channel.bulk is not None for channel in self.channels)

    @property
    def services(self) -> list[ServiceBridge]:
        """Every service bridge."""
        return [h.service for h in self.handles if h.service is not None]

    def add(self, spec: BridgeSpec) -> BridgeHandle:
        """Create the channels (or service bridge) of ``spec`` and start them.

        ``spec``'s fields are checked as the YAML parser checks an entry's; its direction may
        be the YAML spelling (``"GZ_TO_ROS"``, the deprecated ``"IGN_TO_ROS"`` with a warning).

        Raises:
            ConfigError: the spec cannot be bridged (a field of the wrong type or value, an
                unsupported type pair, a bad name, what an earlier entry bridges already);
                nothing of it is left open.
            BridgeError: the bridge is closed.
        """
        checked = checked_spec(spec, self._logger.warning)
        with self._lock:
            if self._closed:
                msg = f"the bridge is closed; {spec!r} was not added"
                raise BridgeError(msg)
            keys = self._keys(checked)
            self._share.claim(checked, keys)  # this bridge's, and every other's on the node
            try:
                handle = (
                    self._add_service(checked)
                    if isinstance(checked, ServiceBridgeSpec)
                    else self._add_topic(checked)
                )
            except BaseException:
                self._share.release(checked)
                raise
            self._handles.append(handle)
            return handle

    def add_all(self, specs: Iterable[BridgeSpec]) -> list[ConfigError]:
        """Add every spec; a spec that fails is logged and skipped. Returns the failures."""
        failures = []
        for spec in specs:
            try:
                self.add(spec)
            except ConfigError as err:
                failures.append(err)
                self._logger.error(str(err))
        return failures

    def remove(self, handle: BridgeHandle) -> None:
        """Close what ``handle`` created. Unknown or already removed handles are ignored."""
        with self._lock:
            if handle not in self._handles:
                return
            self._handles.remove(handle)
            self._share.release(handle.spec)
        _close_handle(handle)

    def heartbeat(self) -> None:
        """Re-evaluate lazy channels (called by the bridge's timer)."""
        for channel in self.channels:
            if channel.lazy:
                try:
                    channel.heartbeat()
                except Exception as err:
                    self._logger.error(f"{channel.describe()}: lazy check failed: {err}")

    def explain(self) -> None:
        """Set every channel's flow state and causes, logging new causes (the bridge's timer)."""
        if self._explainer is None:
            return
        try:
            self._explainer.evaluate(self.channels)
            self._explain_services()
        except Exception as err:
            self._logger.error(f"explaining the channels failed: {err!r}")

    def _explain_services(self) -> None:
        """Say once, as soon as it is seen, what keeps a service bridge from being used: its
        Gazebo providers take other types (it was said only when a call failed, its timeout
        later), or a ROS node uses its name with another service type (a client of another
        type never sees the service: its wait_for_service times out, without a word)."""
        services = self.services
        if not services:
            return
        graph = dict(self.ros_node.get_service_names_and_types())
        said: dict[tuple[int, str], str] = {}
        for service in services:
            why, fault = service.provider_problem()
            ours = service.spec.ros_type
            others = [t for t in graph.get(service.service_name, []) if t != ours]
            causes = {
                "gazebo": f"waiting for Gazebo: {why}" if fault else "",
                "ros": f"a ROS node uses {service.service_name} with {', '.join(others)}, but "
                f"the bridge serves {ours}: a client of another type never sees the service "
                f"(its wait_for_service times out); have it use {ours}, or bridge the service "
                "with its type"
                if others
                else "",
            }
            for kind, text in causes.items():
                key = (id(service), kind)
                if text and self._services_said.get(key) != text:
                    self._logger.warning(f"{service.describe()}: {text}")
                if text:
                    said[key] = text
        self._services_said = said

    def close(self) -> None:
        """Close every bridge, the heartbeat timer and the Gazebo node if the bridge made it."""
        with self._lock:
            if self._closed:
                return
            self._closed = True
            handles, self._handles = self._handles, []
            for handle in handles:
                self._share.release(handle.spec)
            self._share.give_back(self._number)
        self.ros_node.destroy_timer(self._timer)
        if self._explain_timer is not None:
            self.ros_node.destroy_timer(self._explain_timer)
        for handle in reversed(handles):
            _close_handle(handle)
        if self._side is not None:
            self._side.close()
        if self._native is not None:
            self._native.destroy_node()
        if self._owns_gz_node:
            self.gz_node.close()

    def __enter__(self) -> Bridge:
        """``with Bridge(node) as bridge:`` closes it at the end of the block."""
        return self

    def __exit__(self, *_exc: object) -> None:
        """:meth:`close`; an exception of the block goes on."""
        self.close()

    def _add_topic(self, spec: TopicBridgeSpec) -> BridgeHandle:
        try:
            layouts = self.registry.layouts(spec.ros_type, spec.gz_type, garden=self.options.garden)
        except UnsupportedTypeError as err:
            raise UnsupportedTypeError(
                _failed_text(spec, err.message), spec.source or None
            ) from None
        lazy = self.options.lazy if spec.lazy is None else spec.lazy
        handle = BridgeHandle(spec)
        kinds: list[type[Channel]] = []
        if spec.direction in (Direction.BIDIRECTIONAL, Direction.GZ_TO_ROS):
            kinds.append(GzToRosChannel)
        if spec.direction in (Direction.BIDIRECTIONAL, Direction.ROS_TO_GZ):
            kinds.append(RosToGzChannel)
        try:
            for kind in kinds:
                channel = kind(self._ctx, spec, layouts, lazy)
                handle.channels.append(channel)
                self._guard_loops(channel, handle.channels)
                channel.start()
        except Exception as err:
            _close_handle(handle)
            why = _failed_text(spec, str(err), self.options.types_fixed_by)
            raise ConfigError(why, spec.source or None) from err
        for channel in handle.channels:  # once they exist: a refused entry is not "Creating"
            for line in channel.creation_lines():
                self._logger.info(line)
        return handle

    def _keys(self, spec: BridgeSpec) -> list[Key]:
        """What ``spec`` would bridge (none when a name does not resolve: building says why)."""
        try:
            if isinstance(spec, ServiceBridgeSpec):
                return [service_key(self.ros_node.resolve_service_name(spec.service))]
            ros_topic = self._ctx.resolve(spec.ros_topic)
            return topic_keys(spec, ros_topic, self.gz_node.fqn(spec.gz_topic))
        except Exception:
            return []

    def _native_node(self) -> Any:
        with self._lock:
            if self._native is None:
                self._native = unspun_node(self.ros_node, self._number)
            return self._native

    def _side_node(self) -> SideNode:
        with self._lock:
            if self._side is None:
                self._side = SideNode(self.ros_node, self._number)
            return self._side

    def _guard_loops(self, new: Channel, siblings: list[Channel]) -> None:
        """Turn the loop guard on wherever this bridge both publishes and reads a ROS topic."""
        same_topic = [c for c in self.channels + siblings if c.ros_topic == new.ros_topic]
        if any(isinstance(c, GzToRosChannel) for c in same_topic):
            for channel in same_topic:
                if isinstance(channel, RosToGzChannel):
                    channel.enable_loop_guard()

    def _add_service(self, spec: ServiceBridgeSpec) -> BridgeHandle:
        try:
            pair = self.registry.get_service(spec.ros_type)
        except UnsupportedTypeError as err:
            msg = f"Failed to create a bridge for service [{spec.service}]: {err.message}"
            raise UnsupportedTypeError(msg, spec.source or None) from None
        try:
            service = ServiceBridge(
                self._side_node(),
                self.gz_node,
                spec,
                pair,
                self.options.service_timeout,
                max_queued_bytes=self.options.max_queued_bytes,
                ros_types_for=self.registry.ros_service_types_for,
            )
        except ConfigError:
            raise
        except Exception as err:
            msg = (
                f"Failed to create a bridge for service [{spec.service}] with ROS2 type "
                f"[{spec.ros_type}]: {err}"
            )
            raise ConfigError(msg, spec.source or None) from err
        for line in service.creation_lines():
            self._logger.info(line)
        return BridgeHandle(spec, service=service)


def _failed_text(spec: TopicBridgeSpec, why: str, program: str = "") -> str:
    reason = RCL_SOURCE_LOCATION.sub("", why)
    return (
        f"Failed to create a bridge for topic [{spec.ros_topic}] with ROS2 type [{spec.ros_type}] "
        f"to topic [{spec.gz_topic}] with Gazebo Transport type [{spec.gz_type}]: "
        f"{reason}{refused_name_fix(spec, reason, program)}"
    )


def _close_handle(handle: BridgeHandle) -> None:
    for channel in reversed(handle.channels):
        channel.close()
    if handle.service is not None:
        handle.service.close()

"""A Gazebo->ROS channel: Gazebo subscription -> converter -> ROS publisher.

Each message is decoded, converted and published on the channel's own delivery thread (see
:mod:`~ros_gz_bridge_py.core.channel`), in the layout of the spelling it arrived with; images
and point clouds take the bulk path unless ``BridgeOptions.bulk_path`` is off; other messages
are serialized by the compiled CDR writer unless ``BridgeOptions.cdr_write`` is off. Pairs a
native program expresses run their per-message loop natively where the extension is built
(``BridgeOptions.native``, docs/native.md): the channel's Python path then takes only what the
native loop hands back.
"""

from __future__ import annotations

import contextlib
import os
import threading
import time
from collections.abc import Callable
from typing import Any

from rclpy.qos import QoSProfile

from ros_gz_bridge_py.bulk.path import gz_to_ros_cdr
from ros_gz_bridge_py.config import Direction, TopicBridgeSpec
from ros_gz_bridge_py.converters.census import census_for
from ros_gz_bridge_py.converters.registry import Pair
from ros_gz_bridge_py.core.channel import Channel, ChannelContext, delivery_capacity
from ros_gz_bridge_py.errors import ConversionError, UndecodableError
from ros_gz_bridge_py.msgs import message_class
from ros_gz_bridge_py.native.channel import native_programs
from ros_gz_bridge_py.native.pump import ChannelPump
from ros_gz_bridge_py.ros.qos import PUBLISHER_OVERRIDES, gz_to_ros_publisher_qos
from ros_gz_bridge_py.ros.serialized_publisher import SerializedPublisher, object_publisher
from ros_gz_bridge_py.transport import MessageInfo, Subscription


def has_top_level_header(ros_class: type[Any]) -> bool:
    fields: dict[str, str] = ros_class.get_fields_and_field_types()
    return fields.get("header") == "std_msgs/Header"


class GzToRosChannel(Channel):
    """Gazebo subscription -> converter -> ROS publisher.

    Each message is decoded in the layout of the spelling it arrived with (a Fortress
    ``ignition.msgs.IMU`` is not laid out as a Harmonic ``gz.msgs.IMU``).
    """

    direction = Direction.GZ_TO_ROS
    label = "GZ->ROS"

    def __init__(
        self, ctx: ChannelContext, spec: TopicBridgeSpec, layouts: dict[str, Pair], lazy: bool
    ) -> None:
        super().__init__(ctx, spec, layouts, lazy)
        self._gz_class = message_class(self.pair.gz_type)
        #: Wire type -> (pair, gz message class) to read it with.
        self._readers = {
            name: (pair, message_class(pair.gz_type)) for name, pair in layouts.items()
        }
        #: Wire type -> the census of its lists, counted before the parse (converters/census.py).
        self._censuses = {
            name: census
            for name, pair in layouts.items()
            if (census := census_for(pair.to_ros, pair.gz_type)) is not None
        }
        self._qos = gz_to_ros_publisher_qos(self.ros_topic, spec.qos_profile, spec.publisher_queue)
        self._publisher: Any = None
        self._publish: Callable[[Any], None] = _closed_publish
        self._subscription: Subscription | None = None
        self._finish = self._make_finisher()
        #: The native programs of the wire spellings, where this channel takes the native path.
        self._programs = (
            native_programs(
                layouts,
                ctx.options,
                ctx.gz_node,
                frame_id=spec.frame_id or ctx.options.override_frame_id,
            )
            if self.bulk is None
            else {}
        )
        self._pump: ChannelPump | None = None
        #: Converted messages ROS did not publish (``_unpublished``).
        self._not_published = 0
        self._said_shut_down = False

    @property
    def native(self) -> bool:
        """Whether the channel's messages take the native path (docs/native.md)."""
        return bool(self._programs)

    def _names(self, ros_topic: str) -> str:
        spec = self.spec
        return f"[{spec.gz_topic} ({spec.gz_type}) -> {ros_topic} ({spec.ros_type})]"

    @property
    def dropped(self) -> int:
        taken = self._subscription.dropped if self._subscription is not None else 0
        return taken + self._not_published

    @property
    def qos(self) -> QoSProfile:
        return self._qos

    def _make_finisher(self) -> Callable[[Any], None] | None:
        """The per-message header rewrite the node options ask for, bound once."""
        frame_id = self.spec.frame_id or self.ctx.options.override_frame_id
        stamp = self.ctx.options.override_timestamps_with_wall_time
        if not (frame_id or stamp) or not has_top_level_header(self.pair.ros_class):
            return None

        def finish(msg: Any) -> None:
            if frame_id:
                msg.header.frame_id = frame_id
            if stamp:
                sec, nanosec = divmod(time.time_ns(), 1_000_000_000)
                msg.header.stamp.sec = sec
                msg.header.stamp.nanosec = nanosec

        return finish

    def _open_output(self) -> None:
        node = self.ctx.ros_node
        self._publisher = node.create_publisher(
            self.pair.ros_class,
            self.spec.ros_topic,
            self._qos,
            qos_overriding_options=PUBLISHER_OVERRIDES,
        )
        through_rcl = self.ctx.options.rcl_serialized_publish
        if self.bulk is not None:
            publisher = SerializedPublisher(self._publisher, through_rcl=through_rcl)
        elif self.ctx.options.cdr_write:
            publisher = object_publisher(
                self._publisher, self.pair.ros_class, through_rcl=through_rcl
            )
        else:
            publisher = self._publisher
        own = self.ctx.own_publications(self.ros_topic)
        own.add_rcl_publisher(self._publisher.handle.pointer)
        if self._programs:
            self._pump = ChannelPump(
                topic=self.ctx.gz_node.fqn(self.spec.gz_topic),
                publisher=self._publisher,
                programs=self._programs,
                capacity=delivery_capacity(self._qos.depth),
                max_bytes=self.ctx.options.max_queued_bytes,
                max_rate=1.0 / self._limiter.period if self._limiter is not None else 0.0,
                refused=self._convert_and_publish,
                failed=self._conversion_failed,
                counted=self._counted,
                partition=self.ctx.gz_node.partition,
                name=self.spec.gz_topic,
            )
            own.add_numbered(self._pump)
            self._publish = self._pump.wrap(publisher.publish)
        else:
            self._publish = own.wrap(publisher)

    def _counted(self, received: int, rate_limited: int, published: int) -> None:
        """What the native loop did since it last said (on the loop's thread)."""
        stats = self.stats
        stats.received += received
        stats.rate_limited += rate_limited
        stats.published += published

    def _close_output(self) -> None:
        self._publish = _closed_publish
        own = self.ctx.own_publications(self.ros_topic)
        if self._pump is not None:
            self._pump.close()  # its fallback thread publishes no more
            own.remove_numbered(self._pump)
            self._pump = None
        if self._publisher is not None:
            own.remove_rcl_publisher(self._publisher.handle.pointer)
            self.ctx.ros_node.destroy_publisher(self._publisher)
            self._publisher = None

    def _open_input(self) -> None:
        depth = delivery_capacity(self._qos.depth)
        bulk = self.bulk is not None
        self._subscription = self.ctx.gz_node.subscribe(
            self.spec.gz_topic,
            self._on_gz_payload if bulk else self._on_gz_message,
            self.spec.gz_type,
            ignore_local=True,
            queue_size=depth,
            queue_bytes=self.ctx.options.max_queued_bytes,
            copy=False,
            on_delivery_start=(lambda: yield_cpu_to_light_topics(self.ctx.options.bulk_nice))
            if bulk
            else None,
            on_reject=self._rejected,
            native=self._pump,
            large_messages=bulk,
        )

    def _close_input(self) -> None:
        if self._subscription is not None:
            self._subscription.close()
            self._subscription = None

    def _output_has_subscribers(self) -> bool:
        return any(
            (info.node_name, info.node_namespace) not in self.ctx.own_nodes
            for info in self.ctx.ros_node.get_subscriptions_info_by_topic(self.ros_topic)
        )

    def _on_gz_message(self, payload: Any, info: MessageInfo) -> None:
        if not self.limited():
            self._convert_and_publish(payload, info)

    def _convert_and_publish(self, payload: Any, info: MessageInfo) -> None:
        """The Python path of one admitted message: decode, convert, publish, or count why
        not."""
        pair, gz_class = self._readers.get(info.msg_type, (self.pair, self._gz_class))
        census = self._censuses.get(info.msg_type)
        if census is not None:
            try:
                census.check(payload)  # a list too large is refused before it is parsed
            except ConversionError as err:
                self._conversion_failed(err)
                return
        try:
            gz_msg = gz_class.FromString(payload)
        except Exception as err:
            self._conversion_failed(
                UndecodableError(
                    f"undecodable {info.msg_type} payload of {len(payload)} bytes: {err}"
                )
            )
            return
        try:
            ros_msg = pair.to_ros(gz_msg)
            if self._finish is not None:
                self._finish(ros_msg)
        except Exception as err:
            self._conversion_failed(err)
            return
        self._publish_counted(ros_msg)

    def _on_gz_payload(self, payload: Any, info: MessageInfo) -> None:
        """The bulk path: Gazebo payload straight to a serialized ROS message."""
        if self.limited():
            return
        assert self.bulk is not None  # subscribed this way only with a bulk path
        gz_class = self._readers.get(info.msg_type, (self.pair, self._gz_class))[1]
        try:
            cdr = gz_to_ros_cdr(self.bulk, gz_class, memoryview(payload), self._finish)
        except Exception as err:
            self._conversion_failed(err)
            return
        self._publish_counted(cdr)

    def _publish_counted(self, msg: Any) -> None:
        """Publish one converted message, or count it as dropped when ROS does not take it."""
        try:
            self._publish(msg)
        except Exception as err:
            self._unpublished(err)
            return
        self.stats.published += 1

    def _unpublished(self, err: Exception) -> None:
        """A message ROS would not publish: dropped, and said once when ROS was shut down
        under the bridge (``rclpy.shutdown`` before :meth:`Bridge.close`: every message fails
        from then on), else at most every ERROR_LOG_PERIOD s."""
        with self._error_lock:
            self._not_published += 1
            count = self._not_published
            say = self._error_log.ready("publish")
        if not self.ctx.ros_node.context.ok():
            if not self._said_shut_down:
                self._said_shut_down = True
                self._logger.warning(
                    f"{self.describe()}: ROS was shut down before the bridge was closed; "
                    "messages from Gazebo are dropped until it is (close the bridge before "
                    "rclpy.shutdown)"
                )
        elif say:
            self._logger.warning(
                f"{self.describe()}: ROS did not publish a message: {err} ({count} dropped so far)"
            )


def yield_cpu_to_light_topics(nice: int) -> None:
    """Lower the calling thread's CPU priority by ``nice`` (Linux, per thread; 0: unchanged).

    The delivery thread of an image or point cloud channel spends milliseconds of CPU per
    message (copies, the DDS write); on a busy machine that would delay ``/clock`` and the
    other light topics, in this process and in the processes that receive them. Raising a
    thread's own nice value needs no privilege; where it is not possible nothing changes.
    """
    if nice <= 0:
        return
    with contextlib.suppress(OSError, AttributeError):
        tid = threading.get_native_id()
        os.setpriority(os.PRIO_PROCESS, tid, os.getpriority(os.PRIO_PROCESS, tid) + nice)


def _closed_publish(_msg: Any) -> None:
    """Publishing after close: nothing to do (a late message from the delivery thread)."""

"""A ROS->Gazebo channel: ROS subscription -> converter -> Gazebo publisher.

Messages arrive on the executor as serialized CDR (read with the light reader, or through the
bulk path for images and point clouds) or as rclpy's message objects; where the Gazebo lines
lay a message out differently (the IMU), each spelling a subscriber needs is converted on its
own (docs/protocol-lines.md §9.4).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from rclpy.qos import QoSProfile
from rclpy.qos_overriding_options import QoSOverridingOptions
from rclpy.serialization import deserialize_message

from ros_gz_bridge_py.bulk.path import ros_cdr_to_gz
from ros_gz_bridge_py.config import Direction, TopicBridgeSpec
from ros_gz_bridge_py.converters.registry import Pair
from ros_gz_bridge_py.core.channel import Channel, ChannelContext, ChannelState, delivery_capacity
from ros_gz_bridge_py.native.abi import rmw_layout_fits, ros_functions
from ros_gz_bridge_py.native.channel import native_encoders
from ros_gz_bridge_py.native.ros_pump import RosChannelPump
from ros_gz_bridge_py.ros import light_reader
from ros_gz_bridge_py.ros.qos import (
    SUBSCRIPTION_OVERRIDES,
    apply_subscription_overrides,
    endpoint_qos,
)
from ros_gz_bridge_py.transport import Publisher


class RosToGzChannel(Channel):
    """ROS subscription -> converter -> Gazebo publisher.

    With the loop guard on (the bridge also publishes this ROS topic from Gazebo), the
    subscription takes rclpy's message info to skip the bridge's own publications; such
    callbacks run on the side node, because the EventsExecutor cannot call them.
    """

    direction = Direction.ROS_TO_GZ
    label = "ROS->GZ"

    def __init__(
        self, ctx: ChannelContext, spec: TopicBridgeSpec, layouts: dict[str, Pair], lazy: bool
    ) -> None:
        super().__init__(ctx, spec, layouts, lazy)
        #: Where the spellings differ in layout (the IMU), each is converted on its own.
        self._per_spelling = len({id(pair) for pair in layouts.values()}) > 1
        self._qos = endpoint_qos(spec.qos_profile, spec.subscriber_queue)
        self._own = ctx.own_publications(self.ros_topic)
        self._gz_publisher: Publisher | None = None
        self._light = (
            ctx.options.light_read
            and self.bulk is None
            and light_reader.reader_for(self.pair.ros_class) is not None
        )
        #: Native encoders of the wire spellings, where the light read's CDR is encoded in C
        #: (docs/native.md §6): no light tree, converter or protobuf objects per message.
        self._encoders = native_encoders(layouts, ctx.options) if self._light else {}
        #: Whether a native loop takes the messages, encodes and sends them itself
        #: (docs/native.md §7): where the encoders are, the backend gives publishers a
        #: socket of their own, and the loaded rmw lays out what the loop declares.
        self._native_loop = (
            bool(self._encoders)
            and ctx.gz_node.runs_native_loops
            and ctx.options.rcl_serialized_publish
            and ros_functions() is not None
            and rmw_layout_fits()
        )
        self._pump: RosChannelPump | None = None
        self._subscription: Any = None
        self._subscription_node: Any = None
        self._announced = False
        self._dropped = 0  # by the native loop: no memory to copy a message for Python
        self.loop_guard = False

    @property
    def native(self) -> bool:
        """Whether a native loop carries the channel's messages (docs/native.md §7)."""
        return self._native_loop

    def enable_loop_guard(self) -> None:
        """Start skipping the bridge's own publications (re-subscribing if open; a native loop
        skips them by publisher GID and needs nothing more)."""
        if self.loop_guard:
            return
        self.loop_guard = True
        self._own.guard()
        if self.state is ChannelState.ACTIVE and not self._native_loop:
            self._close_input()
            self._open_input()

    def _names(self, ros_topic: str) -> str:
        spec = self.spec
        return f"[{ros_topic} ({spec.ros_type}) -> {spec.gz_topic} ({spec.gz_type})]"

    def _open_output(self) -> None:
        """The Gazebo publisher; for a pair of large messages (a bulk pair: images, point
        clouds) with a send queue per subscriber of ``max_queued_bytes`` (docs/protocol-zmq-data.md
        §2.8.8), so a Gazebo subscriber that stops reading costs the bridge that much."""
        large = self.pair.bulk is not None
        self._gz_publisher = self.ctx.gz_node.advertise(
            self.spec.gz_topic,
            self.spec.gz_type,
            own_socket=self._native_loop,
            queue_bytes=self.ctx.options.max_queued_bytes if large else 0,
        )

    def _close_output(self) -> None:
        if self._gz_publisher is not None:
            self._gz_publisher.close()
            self._gz_publisher = None

    def _open_input(self) -> None:
        if self._native_loop:
            self._open_native_input()
            return
        callback: Callable[..., None]
        overrides: QoSOverridingOptions | None = SUBSCRIPTION_OVERRIDES
        if self.loop_guard:
            # The overrides are the bridge node's parameters, not the side node's; so is the
            # name: the side node takes the one the bridge node resolved (its remap rules).
            apply_subscription_overrides(self.ctx.ros_node, self.spec.ros_topic, self._qos)
            node, name, overrides = self.ctx.side_node(), self.ros_topic, None
            callback = self._on_ros_message_guarded
        else:
            node, name, callback = self.ctx.ros_node, self.spec.ros_topic, self._on_ros_message
        self._subscription = node.create_subscription(
            self.pair.ros_class,
            name,
            callback,
            self._qos,
            qos_overriding_options=overrides,
            raw=self.bulk is not None or self._light,
        )
        self._subscription_node = node

    def _open_native_input(self) -> None:
        """The subscription on the node no executor spins, and the loop that takes from it."""
        apply_subscription_overrides(self.ctx.ros_node, self.spec.ros_topic, self._qos)
        node = self.ctx.native_node()
        self._subscription = node.create_subscription(
            self.pair.ros_class, self.ros_topic, _taken_natively, self._qos, raw=True
        )
        self._subscription_node = node
        own = self._own
        self._pump = RosChannelPump(
            subscription=self._subscription,
            publisher=self._gz_publisher,
            encoders=self._encoders,
            max_rate=1.0 / self._limiter.period if self._limiter is not None else 0.0,
            refused=self._convert_and_publish,
            capacity=delivery_capacity(self._qos.depth),
            max_bytes=self.ctx.options.max_queued_bytes,
            counted=self._counted,
            lost=self._lost,
            failed=self._native_failed,
            own_publishers=own.rcl_publishers,
            watch_own_publishers=own.watch_rcl_publishers,
            name=self.spec.gz_topic,
        )

    def _counted(
        self, received: int, own_skipped: int, rate_limited: int, published: int, send_failures: int
    ) -> None:
        """What the native loop did since it last said (on its thread); a message whose send
        failed counts among the node's ``send_failures``, as on the Python path. The loop's
        ``received`` holds the bridge's own publications it skipped, which the Python path
        does not count as received (the table showed IN above OUT by them, unexplained)."""
        stats = self.stats
        stats.received += received - own_skipped
        stats.own_skipped += own_skipped
        stats.rate_limited += rate_limited
        stats.published += published
        if send_failures:
            self.ctx.gz_node.count("send_failures", send_failures)
        if published and not self._announced:
            self._announce()

    def _lost(self, count: int) -> None:
        """Messages the native loop left to the Python path and dropped on their way (no
        memory to copy them, or the oldest past the bounds of their queue, on the loop's
        thread): among the channel's drops, and said."""
        self._dropped += count
        self._logger.warning(
            f"{self.describe()}: {count} message(s) dropped on their way to the Python path "
            "(no memory to copy them, or past the bounds of its queue)"
        )

    def _native_failed(self, reason: str) -> None:
        """The native loop took the channel off: said, and kept as the channel's last error."""
        self.stats.last_error = reason
        self._logger.error(f"{self.describe()}: {reason}")

    def _close_input(self) -> None:
        if self._pump is not None:
            self._pump.close()
            self._pump = None
        if self._subscription is not None:
            self._subscription_node.destroy_subscription(self._subscription)
            self._subscription = None

    @property
    def dropped(self) -> int:
        return self._dropped

    @property
    def qos(self) -> QoSProfile:
        return self._qos

    def gazebo_subscribed(self) -> bool:
        """True while some remote Gazebo subscriber takes this channel's messages."""
        return self._gz_publisher is not None and bool(self._gz_publisher.wire_types())

    @property
    def send_queue(self) -> int:
        """Messages queued at most for each Gazebo subscriber (0: none, or not open)."""
        return self._gz_publisher.send_queue() if self._gz_publisher is not None else 0

    def _output_has_subscribers(self) -> bool:
        return self._gz_publisher is not None and self._gz_publisher.has_connections()

    def _on_ros_message_guarded(self, ros_msg: Any, info: Any) -> None:
        if self._own.is_own(info, ros_msg):
            self.stats.own_skipped += 1
            return
        self._on_ros_message(ros_msg)

    def _on_ros_message(self, ros_msg: Any) -> None:
        """``ros_msg`` is a message object, or its CDR bytes (bulk path, light read)."""
        if not self.limited():
            self._convert_and_publish(ros_msg)

    def _convert_and_publish(self, ros_msg: Any) -> None:
        """The Python path of one admitted message: convert, publish, or count why not."""
        publisher = self._gz_publisher
        if publisher is None:
            return
        try:
            if self.bulk is not None:
                self._publish_serialized(publisher, ros_msg)
            elif self._encoders and self._publish_encoded(publisher, ros_msg):
                pass
            else:
                msg = self._read(ros_msg) if self._light else ros_msg
                if self._per_spelling:
                    self._publish_per_spelling(publisher, msg)
                else:
                    publisher.publish(self.pair.to_gz(msg))
        except Exception as err:
            self._conversion_failed(err)
            return
        self.stats.published += 1
        if not self._announced:
            self._announce()

    def _announce(self) -> None:
        self._announced = True
        pair = (self.spec.ros_type, self.spec.gz_type)
        if pair in self.ctx.passing_shown:
            return
        self.ctx.passing_shown.add(pair)
        self._logger.info(
            f"Passing message from ROS {self.spec.ros_type} to Gazebo {self.spec.gz_type} "
            "(showing msg only once per type)"
        )

    def _publish_encoded(self, publisher: Publisher, cdr: bytes) -> bool:
        """Encode natively and publish, in each spelling the layouts need; False (nothing
        sent) where an encoder leaves the message to the Python path."""
        if not self._per_spelling:
            status, payload = self._encoders[publisher.msg_type].to_pb(cdr)
            if status or payload is None:
                return False
            publisher.publish_raw(payload)
            return True
        payloads = {}
        for wire_type in publisher.wire_types() | {publisher.msg_type}:
            status, payload = self._encoders[wire_type].to_pb(cdr)
            if status or payload is None:
                return False
            payloads[wire_type] = payload
        for wire_type, payload in payloads.items():
            publisher.publish_raw(payload, as_type=wire_type)
        return True

    def _publish_per_spelling(self, publisher: Publisher, msg: Any) -> None:
        """Convert once per layout the subscribers need (and the configured one, for local
        subscribers), each sent only in its spelling."""
        for wire_type in publisher.wire_types() | {publisher.msg_type}:
            payload = self.layouts[wire_type].to_gz(msg).SerializeToString()
            publisher.publish_raw(payload, as_type=wire_type)

    def _read(self, cdr: bytes) -> Any:
        """The message in ``cdr`` for ``to_gz``: a light tree, or rclpy's message when the
        encapsulation is not plain little-endian CDR."""
        tree = light_reader.read(cdr, self.pair.ros_class)
        return tree if tree is not None else deserialize_message(cdr, self.pair.ros_class)

    def _publish_serialized(self, publisher: Publisher, cdr: bytes) -> None:
        assert self.bulk is not None  # subscribed raw only with a bulk path
        payload = ros_cdr_to_gz(self.bulk, self.pair.ros_class, cdr)
        if payload is None:  # not plain CDR: the object path
            publisher.publish(self.pair.to_gz(self._read(cdr)))
        else:
            publisher.publish_raw(payload)


def _taken_natively(_msg: Any) -> None:
    """The callback of a native loop's subscription: no executor spins its node, so it is
    never called (the loop takes the messages itself)."""

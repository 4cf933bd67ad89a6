"""Channels: one direction of one bridged topic.

A channel pairs a ROS endpoint with a Gazebo Transport endpoint through one converter pair. The
output side (the ROS publisher of a Gazebo->ROS channel, the Gazebo publisher of a ROS->Gazebo
channel) exists for the channel's whole life. The input side is opened at start, or, for a lazy
channel, only while the output side has subscribers other than the bridge itself; the bridge
re-checks that every heartbeat (:meth:`Channel.heartbeat`). Each channel owns its endpoints and
closes exactly those (never "everything on this topic").

Threads: Gazebo->ROS messages are decoded, converted and published on the channel's own
delivery thread (a bounded, drop-oldest queue in the transport; over ZeroMQ the same thread
reads the topic's own socket), so a heavy topic never delays a light one and never touches
the ROS executor. ROS->Gazebo messages arrive on the executor.
The queue holds at least :data:`MIN_DELIVERY_QUEUE` messages (more if the publisher depth is
larger) within the transport's byte budget (64 MiB): a burst, or the bridge's threads losing
the CPU for tens of milliseconds at kilohertz rates, is absorbed instead of dropped, and a flood
of images still keeps only the newest ~10 frames. (The C++ bridge blocks its receive thread
instead, so ZeroMQ buffers up to 1000 messages of every topic behind a slow one; our queue
holds as many, per topic.)

Pairs with a bulk path (Image, PointCloud2) take it unless ``BridgeOptions.bulk_path`` is off:
serialized messages on the ROS side, the bulk bytes copied once, and the DDS write made with
the GIL released (see :mod:`ros_gz_bridge_py.bulk`). The other ROS->Gazebo channels take the
serialized message too and read it with :mod:`ros_gz_bridge_py.ros.light_reader` (several
times cheaper than rclpy's message objects) unless ``BridgeOptions.light_read`` is off.
"""

from __future__ import annotations

import abc
import contextlib
import enum
import os
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

from rclpy.qos import QoSProfile
from rclpy.serialization import deserialize_message

from ros_gz_bridge_py.bulk.path import BulkPath, gz_to_ros_cdr, ros_cdr_to_gz
from ros_gz_bridge_py.bulk.serialized_publisher import SerializedPublisher
from ros_gz_bridge_py.config import Direction, TopicBridgeSpec
from ros_gz_bridge_py.converters.registry import Pair
from ros_gz_bridge_py.core.diagnosis import Finding, Flow
from ros_gz_bridge_py.core.loop_guard import OwnPublications
from ros_gz_bridge_py.core.options import BridgeOptions
from ros_gz_bridge_py.errors import ConversionError
from ros_gz_bridge_py.msgs import message_class
from ros_gz_bridge_py.ros import light_reader
from ros_gz_bridge_py.ros.qos import (
    PUBLISHER_OVERRIDES,
    SUBSCRIPTION_OVERRIDES,
    endpoint_qos,
    gz_to_ros_publisher_qos,
)
from ros_gz_bridge_py.transport import GzNode, MessageInfo, Publisher, Subscription

#: Minimum seconds between two log lines about conversion errors of one channel.
ERROR_LOG_PERIOD = 5.0
#: Fewest messages a Gazebo->ROS delivery queue holds: ZeroMQ's default high-water mark, so
#: 200 ms at 5 kHz (measured: with 100, a 5 kHz Odometry channel dropped 5-9% on 2 busy cores).
MIN_DELIVERY_QUEUE = 1000


class ChannelState(enum.Enum):
    CREATED = "created"
    ACTIVE = "active"
    LAZY_IDLE = "lazy_idle"
    CLOSED = "closed"


@dataclass
class ChannelStats:
    """Counters of one channel; plain ints updated from one thread each, read from any."""

    received: int = 0
    published: int = 0
    conversion_errors: int = 0
    own_skipped: int = 0
    last_error: str = ""
    started_at: float = field(default_factory=time.monotonic)

    def as_dict(self) -> dict[str, int | float | str]:
        return {
            "received": self.received,
            "published": self.published,
            "conversion_errors": self.conversion_errors,
            "own_skipped": self.own_skipped,
            "last_error": self.last_error,
        }


def _own_publications_table() -> Callable[[str], OwnPublications]:
    table: dict[str, OwnPublications] = {}
    lock = threading.Lock()

    def get(topic: str) -> OwnPublications:
        with lock:
            return table.setdefault(topic, OwnPublications())

    return get


@dataclass
class ChannelContext:
    """What channels share: the nodes and the bridge's options."""

    ros_node: Any
    gz_node: GzNode
    #: The bridge's side node (created on first use), for subscriptions that need message info.
    side_node: Callable[[], Any]
    options: BridgeOptions
    #: (name, namespace) of the bridge's own ROS nodes, left out when counting readers.
    own_nodes: frozenset[tuple[str, str]] = frozenset()
    #: OwnPublications per resolved ROS topic, shared by the two halves of a bidirectional bridge.
    own_publications: Callable[[str], OwnPublications] = field(
        default_factory=_own_publications_table
    )

    def resolve(self, ros_topic: str) -> str:
        return str(self.ros_node.resolve_topic_name(ros_topic))


class Channel(abc.ABC):
    """One direction of one topic: lifecycle, lazy switching and counters.

    ``layouts`` gives the pair that reads and writes each spelling of the Gazebo type on the
    wire (``Registry.layouts``); ``pair`` is the one of the configured spelling.
    """

    direction: Direction

    def __init__(
        self, ctx: ChannelContext, spec: TopicBridgeSpec, layouts: dict[str, Pair], lazy: bool
    ) -> None:
        self.ctx = ctx
        self.spec = spec
        self.layouts = layouts
        self.pair = layouts[spec.gz_type]
        self.lazy = lazy
        self.state = ChannelState.CREATED
        self.stats = ChannelStats()
        #: What the bridge's explainer last made of the channel (``explain.py``).
        self.flow: Flow | None = None
        self.findings: list[Finding] = []
        self.ros_topic = ctx.resolve(spec.ros_topic)
        self._logger = ctx.ros_node.get_logger()
        self._last_error_log = 0.0
        self.bulk: BulkPath | None = self.pair.bulk if ctx.options.bulk_path else None

    def start(self) -> None:
        """Open the output side, and the input side unless the channel is lazy."""
        self._open_output()
        if self.lazy:
            self.state = ChannelState.LAZY_IDLE
            self.heartbeat()
        else:
            self._open_input()
            self.state = ChannelState.ACTIVE

    def heartbeat(self) -> None:
        """Lazy channels: open or close the input side as the output gains or loses readers."""
        if not self.lazy or self.state is ChannelState.CLOSED:
            return
        wanted = self._output_has_subscribers()
        if wanted and self.state is ChannelState.LAZY_IDLE:
            self._logger.debug(f"Bridge [{self.ros_topic}] - Subscriptions found, starting bridge")
            self._open_input()
            self.state = ChannelState.ACTIVE
        elif not wanted and self.state is ChannelState.ACTIVE:
            self._logger.debug(
                f"Bridge [{self.ros_topic}] - No subscriptions found, stopping bridge"
            )
            self._close_input()
            self.state = ChannelState.LAZY_IDLE

    def close(self) -> None:
        if self.state is ChannelState.CLOSED:
            return
        if self.state is ChannelState.ACTIVE:
            self._close_input()
        self._close_output()
        self.state = ChannelState.CLOSED

    def _conversion_failed(self, err: Exception) -> None:
        self.stats.conversion_errors += 1
        self.stats.last_error = str(err)
        now = time.monotonic()
        if now - self._last_error_log >= ERROR_LOG_PERIOD:
            self._last_error_log = now
            self._logger.error(
                f"{self.describe()}: message skipped: {err} "
                f"({self.stats.conversion_errors} conversion errors so far)"
            )

    @abc.abstractmethod
    def describe(self) -> str: ...

    @property
    @abc.abstractmethod
    def qos(self) -> QoSProfile:
        """The QoS of the channel's ROS endpoint."""

    @abc.abstractmethod
    def _open_output(self) -> None: ...

    @abc.abstractmethod
    def _close_output(self) -> None: ...

    @abc.abstractmethod
    def _open_input(self) -> None: ...

    @abc.abstractmethod
    def _close_input(self) -> None: ...

    @abc.abstractmethod
    def _output_has_subscribers(self) -> bool: ...


def has_top_level_header(ros_class: type[Any]) -> bool:
    fields: dict[str, str] = ros_class.get_fields_and_field_types()
    return fields.get("header") == "std_msgs/Header"


class GzToRosChannel(Channel):
    """Gazebo subscription -> converter -> ROS publisher.

    Each message is decoded in the layout of the spelling it arrived with (a Fortress
    ``ignition.msgs.IMU`` is not laid out as a Harmonic ``gz.msgs.IMU``).
    """

    direction = Direction.GZ_TO_ROS

    def __init__(
        self, ctx: ChannelContext, spec: TopicBridgeSpec, layouts: dict[str, Pair], lazy: bool
    ) -> None:
        super().__init__(ctx, spec, layouts, lazy)
        self._gz_class = message_class(self.pair.gz_type)
        #: Wire type -> (pair, gz message class) to read it with.
        self._readers = {
            name: (pair, message_class(pair.gz_type)) for name, pair in layouts.items()
        }
        self._qos = gz_to_ros_publisher_qos(self.ros_topic, spec.qos_profile, spec.publisher_queue)
        self._publisher: Any = None
        self._publish: Callable[[Any], None] = _closed_publish
        self._subscription: Subscription | None = None
        self._finish = self._make_finisher()

    def describe(self) -> str:
        return (
            f"GZ->ROS [{self.spec.gz_topic} ({self.spec.gz_type}) -> "
            f"{self.ros_topic} ({self.spec.ros_type})]"
        )

    @property
    def dropped(self) -> int:
        return self._subscription.dropped if self._subscription is not None else 0

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
        publisher = (
            self._publisher
            if self.bulk is None
            else SerializedPublisher(
                self._publisher, through_rcl=self.ctx.options.rcl_serialized_publish
            )
        )
        self._publish = self.ctx.own_publications(self.ros_topic).wrap(publisher)

    def _close_output(self) -> None:
        self._publish = _closed_publish
        if self._publisher is not None:
            self.ctx.ros_node.destroy_publisher(self._publisher)
            self._publisher = None

    def _open_input(self) -> None:
        depth = max(self._qos.depth, MIN_DELIVERY_QUEUE)
        bulk = self.bulk is not None
        self._subscription = self.ctx.gz_node.subscribe(
            self.spec.gz_topic,
            self._on_gz_payload if bulk else self._on_gz_message,
            self.spec.gz_type,
            ignore_local=True,
            queue_size=depth,
            copy=False,
            on_delivery_start=(lambda: yield_cpu_to_light_topics(self.ctx.options.bulk_nice))
            if bulk
            else None,
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
        self.stats.received += 1
        pair, gz_class = self._readers.get(info.msg_type, (self.pair, self._gz_class))
        try:
            gz_msg = gz_class.FromString(payload)
        except Exception as err:
            self._conversion_failed(
                ConversionError(
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
        self._publish(ros_msg)
        self.stats.published += 1

    def _on_gz_payload(self, payload: Any, info: MessageInfo) -> None:
        """The bulk path: Gazebo payload straight to a serialized ROS message."""
        self.stats.received += 1
        assert self.bulk is not None  # subscribed this way only with a bulk path
        gz_class = self._readers.get(info.msg_type, (self.pair, self._gz_class))[1]
        try:
            cdr = gz_to_ros_cdr(self.bulk, gz_class, memoryview(payload), self._finish)
        except Exception as err:
            self._conversion_failed(err)
            return
        self._publish(cdr)
        self.stats.published += 1


class RosToGzChannel(Channel):
    """ROS subscription -> converter -> Gazebo publisher.

    With the loop guard on (the bridge also publishes this ROS topic from Gazebo), the
    subscription takes rclpy's message info to skip the bridge's own publications; such
    callbacks run on the side node, because the EventsExecutor cannot call them.
    """

    direction = Direction.ROS_TO_GZ

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
        self._subscription: Any = None
        self._subscription_node: Any = None
        self._announced = False
        self.loop_guard = False

    def enable_loop_guard(self) -> None:
        """Start skipping the bridge's own publications (re-subscribing if open)."""
        if self.loop_guard:
            return
        self.loop_guard = True
        if self.state is ChannelState.ACTIVE:
            self._close_input()
            self._open_input()

    def describe(self) -> str:
        return (
            f"ROS->GZ [{self.ros_topic} ({self.spec.ros_type}) -> "
            f"{self.spec.gz_topic} ({self.spec.gz_type})]"
        )

    def _open_output(self) -> None:
        self._gz_publisher = self.ctx.gz_node.advertise(self.spec.gz_topic, self.spec.gz_type)

    def _close_output(self) -> None:
        if self._gz_publisher is not None:
            self._gz_publisher.close()
            self._gz_publisher = None

    def _open_input(self) -> None:
        callback: Callable[..., None]
        if self.loop_guard:
            node, callback = self.ctx.side_node(), self._on_ros_message_guarded
        else:
            node, callback = self.ctx.ros_node, self._on_ros_message
        self._subscription = node.create_subscription(
            self.pair.ros_class,
            self.spec.ros_topic,
            callback,
            self._qos,
            qos_overriding_options=SUBSCRIPTION_OVERRIDES,
            raw=self.bulk is not None or self._light,
        )
        self._subscription_node = node

    def _close_input(self) -> None:
        if self._subscription is not None:
            self._subscription_node.destroy_subscription(self._subscription)
            self._subscription = None

    @property
    def qos(self) -> QoSProfile:
        return self._qos

    def gazebo_subscribed(self) -> bool:
        """True while some remote Gazebo subscriber takes this channel's messages."""
        return self._gz_publisher is not None and bool(self._gz_publisher.wire_types())

    def _output_has_subscribers(self) -> bool:
        return self._gz_publisher is not None and self._gz_publisher.has_connections()

    def _on_ros_message_guarded(self, ros_msg: Any, info: Any) -> None:
        if self._own.is_own(info):
            self.stats.own_skipped += 1
            return
        self._on_ros_message(ros_msg)

    def _on_ros_message(self, ros_msg: Any) -> None:
        """``ros_msg`` is a message object, or its CDR bytes (bulk path, light read)."""
        self.stats.received += 1
        publisher = self._gz_publisher
        if publisher is None:
            return
        try:
            if self.bulk is not None:
                self._publish_serialized(publisher, ros_msg)
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
            self._announced = True
            self._logger.info(
                f"Passing message from ROS {self.spec.ros_type} to Gazebo {self.spec.gz_type} "
                "(showing msg only once per type)"
            )

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

"""Channels: one direction of one bridged topic.

A channel pairs a ROS endpoint with a Gazebo Transport endpoint through one converter pair. The
output side (the ROS publisher of a Gazebo->ROS channel, the Gazebo publisher of a ROS->Gazebo
channel) exists for the channel's whole life. The input side is opened at start, or, for a lazy
channel, only while the output side has subscribers other than the bridge itself; the bridge
re-checks that every heartbeat (:meth:`Channel.heartbeat`). Each channel owns its endpoints and
closes exactly those (never "everything on this topic").

Threads: Gazebo->ROS messages are decoded, converted and published on the channel's own
delivery thread (a bounded, drop-oldest queue in the transport; over ZeroMQ the same thread
reads the topic's own socket), or, for a native channel, on the process's one Gazebo->ROS loop
within a fairness budget (docs/native.md §5), so a heavy topic never starves a light one and
never touches the ROS executor. ROS->Gazebo messages arrive on the executor.
The queue holds at least :data:`MIN_DELIVERY_QUEUE` messages (more if the publisher depth is
larger) within the transport's byte budget (64 MiB): a burst, or the bridge's threads losing
the CPU for tens of milliseconds at kilohertz rates, is absorbed instead of dropped, and a flood
of images still keeps only the newest ~10 frames. (The C++ bridge blocks its receive thread
instead, so ZeroMQ buffers up to 1000 messages of every topic behind a slow one; our queue
holds as many, per topic.)

Pairs with a bulk path (Image, PointCloud2) take it unless ``BridgeOptions.bulk_path`` is off:
serialized messages on the ROS side, the bulk bytes copied at most once, and the DDS write
made with the GIL released (see :mod:`ros_gz_bridge_py.bulk`). The other ROS->Gazebo channels
take the serialized message too and read it with :mod:`ros_gz_bridge_py.ros.light_reader`
(several times cheaper than rclpy's message objects) unless ``BridgeOptions.light_read`` is
off.
"""

from __future__ import annotations

import abc
import enum
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

from rclpy.qos import QoSProfile

from ros_gz_bridge_py.bulk.path import BulkPath
from ros_gz_bridge_py.config import Direction, TopicBridgeSpec
from ros_gz_bridge_py.config.model import MAX_QUEUE_DEPTH
from ros_gz_bridge_py.config.names import renamed
from ros_gz_bridge_py.converters.registry import Pair
from ros_gz_bridge_py.core.diagnosis import Finding, Flow
from ros_gz_bridge_py.core.loop_guard import OwnPublications
from ros_gz_bridge_py.core.options import BridgeOptions
from ros_gz_bridge_py.core.rate_limit import rate_limiter
from ros_gz_bridge_py.errors import SizeMismatchError, UndecodableError
from ros_gz_bridge_py.ros.quick_log import quick_logger
from ros_gz_bridge_py.transport import GzNode, Rejection
from ros_gz_bridge_py.transport.throttle import Throttle

#: Minimum seconds between two log lines about conversion errors of one channel.
ERROR_LOG_PERIOD = 5.0
#: Fewest messages a Gazebo->ROS delivery queue holds: ZeroMQ's default high-water mark, so
#: 200 ms at 5 kHz (measured: with 100, a 5 kHz Odometry channel dropped 5-9% on 2 busy cores).
MIN_DELIVERY_QUEUE = 1000


def delivery_capacity(depth: int) -> int:
    """The messages a channel's delivery queue holds for a ROS endpoint of ``depth``: at least
    :data:`MIN_DELIVERY_QUEUE`, at most ``MAX_QUEUE_DEPTH`` (a ``qos_overrides.*.depth``
    deeper than that keeps its ROS history; the bridge's own queue stops there)."""
    return min(max(depth, MIN_DELIVERY_QUEUE), MAX_QUEUE_DEPTH)


#: What a warning about each kind of error adds: where to look.
_HINTS = {
    Rejection.UNDECODABLE: "; the publisher does not send valid messages of its type",
    Rejection.MALFORMED: "; a process that does not speak Gazebo Transport sends on the topic",
    Rejection.WRONG_TYPE: "; set the bridge's Gazebo type to that one, or stop that publisher",
    Rejection.OVERSIZE: (
        "; if the publisher is legitimate, raise GZ_TRANSPORT_MAX_MESSAGE_SIZE (bytes) in the "
        "bridge's environment"
    ),
}


def conversion_reason(err: Exception) -> Rejection:
    """What was wrong with a message the converter refused."""
    if isinstance(err, UndecodableError):
        return Rejection.UNDECODABLE
    if isinstance(err, SizeMismatchError):
        return Rejection.INCONSISTENT_SIZES
    return Rejection.CONVERSION


class ChannelState(enum.Enum):
    CREATED = "created"
    ACTIVE = "active"
    LAZY_IDLE = "lazy_idle"
    CLOSED = "closed"


@dataclass
class ChannelStats:
    """Counters of one channel; plain ints updated from one thread each, read from any. A
    channel on the native data plane adds its loop's counts about once a second
    (``native/loop.py``), so they may trail the messages by that much.

    Every message the channel could not use counts once in ``errors_by_reason`` under what
    was wrong (:class:`~ros_gz_bridge_py.transport.Rejection`); those the converter refused
    also in ``conversion_errors``, those the transport refused (malformed frames, another
    type, over the size limit) in ``rejected``.
    """

    received: int = 0
    published: int = 0
    conversion_errors: int = 0
    rejected: int = 0
    own_skipped: int = 0
    #: Dropped by ``max_rate`` before conversion.
    rate_limited: int = 0
    last_error: str = ""
    errors_by_reason: dict[str, int] = field(default_factory=dict)
    started_at: float = field(default_factory=time.monotonic)

    @property
    def errors(self) -> int:
        """Every message the channel could not use."""
        return self.conversion_errors + self.rejected

    def as_dict(self) -> dict[str, int | float | str]:
        return {
            "received": self.received,
            "published": self.published,
            "errors": self.errors,
            "conversion_errors": self.conversion_errors,
            "rejected": self.rejected,
            "own_skipped": self.own_skipped,
            "rate_limited": self.rate_limited,
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
    #: The bridge's node that no executor spins (created on first use): the subscriptions of
    #: native ROS -> Gazebo loops, which take their messages themselves (docs/native.md §7).
    native_node: Callable[[], Any]
    options: BridgeOptions
    #: (name, namespace) of the bridge's own ROS nodes, left out when counting readers.
    own_nodes: frozenset[tuple[str, str]] = frozenset()
    #: OwnPublications per resolved ROS topic, shared by the two halves of a bidirectional bridge.
    own_publications: Callable[[str], OwnPublications] = field(
        default_factory=_own_publications_table
    )
    #: (ROS type, Gazebo type) of the ROS->Gazebo channels whose "Passing message" line was
    #: logged: once per pair of types, as the C++ bridge logs it.
    passing_shown: set[tuple[str, str]] = field(default_factory=set)

    def resolve(self, ros_topic: str) -> str:
        return str(self.ros_node.resolve_topic_name(ros_topic))


class Channel(abc.ABC):
    """One direction of one topic: lifecycle, lazy switching and counters.

    ``layouts`` gives the pair that reads and writes each spelling of the Gazebo type on the
    wire (``Registry.layouts``); ``pair`` is the one of the configured spelling.
    """

    direction: Direction
    #: The direction as the C++ bridge's log lines name it: ``GZ->ROS`` or ``ROS->GZ``.
    label: str

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
        self._logger = quick_logger(ctx.ros_node.get_logger())
        # Error counting: from the transport's thread and the delivery thread.
        self._error_lock = threading.Lock()
        self._error_log = Throttle(ERROR_LOG_PERIOD)
        self.bulk: BulkPath | None = self.pair.bulk if ctx.options.bulk_path else None
        self._limiter = rate_limiter(spec.max_rate, ctx.options.max_rate)

    @property
    def native(self) -> bool:
        """Whether a native loop carries the channel's messages (docs/native.md)."""
        return False

    @property
    @abc.abstractmethod
    def dropped(self) -> int:
        """Messages received and dropped so far without a conversion error (the DROPPED
        column of the status table)."""

    def limited(self) -> bool:
        """Count a received message; True (and counted as rate-limited) when ``max_rate``
        drops it. Called first for every message, before decoding or converting."""
        self.stats.received += 1
        if self._limiter is None or self._limiter.admit():
            return False
        self.stats.rate_limited += 1
        return True

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
        """The converter (or the decoder) refused a message: counted under what was wrong."""
        with self._error_lock:
            self.stats.conversion_errors += 1
        self._count_error(conversion_reason(err), str(err))

    def _rejected(self, reason: Rejection, detail: str) -> None:
        """The transport could not use a message of the channel's Gazebo topic (its
        ``on_reject``; called on the transport's thread)."""
        with self._error_lock:
            self.stats.rejected += 1
        self._count_error(reason, detail)

    def _count_error(self, reason: Rejection, detail: str) -> None:
        """Count under ``reason``; a warning per reason at most every ERROR_LOG_PERIOD s."""
        with self._error_lock:
            by_reason = self.stats.errors_by_reason
            by_reason[reason.value] = count = by_reason.get(reason.value, 0) + 1
            self.stats.last_error = detail  # what was wrong: errors_by_reason
            if not self._error_log.ready(reason):
                return
        hint = _HINTS.get(reason, "")
        self._logger.warning(
            f"{self.describe()}: message skipped ({reason.value}): {detail} "
            f"({count} so far, {_errors(self.stats.errors)} in all){hint}"
        )

    def describe(self) -> str:
        """``GZ->ROS [<from> (<type>) -> <to> (<type>)]`` with the resolved ROS name: what the
        channel's own log lines start with."""
        return f"{self.label} {self._names(self.ros_topic)}"

    def creation_lines(self) -> list[str]:
        """What the bridge logs on creating the channel: the C++ bridge's line word for word
        (the names as configured, docs/behaviour.md §5), then, when ROS resolution changed
        the ROS name, a line of ours saying into what."""
        lazy = int(self.lazy)
        lines = [f"Creating {self.label} Bridge: {self._names(self.spec.ros_topic)} (Lazy {lazy})"]
        if renamed(self.spec.ros_topic, self.ros_topic):
            lines.append(
                f"{self.describe()}: the ROS name {self.spec.ros_topic} resolves to "
                f"{self.ros_topic}"
            )
        return lines

    @abc.abstractmethod
    def _names(self, ros_topic: str) -> str:
        """``[<from> (<type>) -> <to> (<type>)]`` in the channel's direction, the ROS side
        named ``ros_topic``."""

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


def _errors(count: int) -> str:
    return "1 error" if count == 1 else f"{count} errors"

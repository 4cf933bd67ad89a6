"""The Gazebo Transport node contract, and what every backend shares (in the manner of
python-can's ``BusABC``).

:class:`GzNode` is named so it cannot be mistaken for rclpy's ``Node``. It owns what is the same
in every backend: the counters, the fully qualified names, the table of local subscriptions,
local (intra-process) delivery, the choice of wire spellings per message (docs/protocol-lines.md
§9), ``has_connections`` and an idempotent ``close``; its service half (blocking calls, handlers,
``node_services.py``) and its discovery half (the graph's queries, waiting for publishers,
``node_graph.py``) are mixed in from modules of their own. A backend implements narrow hooks:
open and close its publishers, subscriptions and service offers, send one message in one
spelling, call a service, and tell what its discovery knows. The contract every backend must
honour is tested by one suite, ``tests/unit/transport/test_node_contract.py``; a new backend is
written by passing it.
"""

from __future__ import annotations

import abc
import collections
import logging
import threading
import uuid
from collections.abc import Callable
from typing import Any, ClassVar, Self

from ros_gz_bridge_py.errors import TransportError
from ros_gz_bridge_py.msgs.names import GENERIC_TYPE, Spelling, spellings
from ros_gz_bridge_py.transport.api import (
    Callback,
    MessageInfo,
    NativeLoop,
    RejectCallback,
    TransportStats,
)
from ros_gz_bridge_py.transport.delivery import (
    MAX_QUEUED_BYTES,
    Deliver,
    Payload,
    raw_deliverer,
    typed_deliverer,
)
from ros_gz_bridge_py.transport.handles import (
    Delivery,
    Publisher,
    Subscription,
    ThreadDelivery,
)
from ros_gz_bridge_py.transport.names import fully_qualified_name
from ros_gz_bridge_py.transport.node_graph import GraphView
from ros_gz_bridge_py.transport.node_services import ServiceEnds
from ros_gz_bridge_py.transport.settings import TransportSettings
from ros_gz_bridge_py.transport.wire_types import SubscriberBook

_LOG = logging.getLogger("ros_gz_bridge_py.transport")


class GzNode(ServiceEnds, GraphView):
    """A Gazebo Transport participant: advertise, subscribe, provide and call services.

    Thread-safe: publishing, ``has_connections``, ``stats`` and every public method may be
    called from any thread; ``request`` not from the node's own thread (it would wait for
    itself). Bad network input never raises: it is counted in ``stats``.
    """

    #: The spelling taken for peers whose Gazebo line nothing tells (None: our own).
    default_peer_spelling: ClassVar[Spelling | None] = None
    #: The backend's subscription handle (a subclass where it keeps more per subscription).
    subscription_class: ClassVar[type[Subscription]] = Subscription
    #: Whether a queued subscription's ``native`` loop reads its messages (ZeroMQ only).
    runs_native_loops: ClassVar[bool] = False

    def __init__(
        self,
        partition: str | None = None,
        namespace: str = "",
        settings: TransportSettings | None = None,
    ) -> None:
        """Raises:
        LocalProtocolError: the partition or namespace is invalid."""
        GraphView.__init__(self)
        self.settings = settings or TransportSettings.from_env()
        self.partition = self.settings.partition if partition is None else partition
        self.namespace = namespace
        fully_qualified_name(self.partition, namespace, "/check")
        self.process_uuid = str(uuid.uuid4())
        self.node_uuid = str(uuid.uuid4())
        #: Remote subscribers per topic and their lines (written by the backend's discovery).
        self.subscriber_book = SubscriberBook(self.default_peer_spelling)
        self._counts: collections.Counter[str] = collections.Counter()
        self._count_lock = threading.Lock()
        # Read by publishing threads without a lock: entries are replaced, never mutated.
        self._subscriptions: dict[str, tuple[Subscription, ...]] = {}
        self._subscriptions_lock = threading.Lock()
        self.closed = False
        self._open()

    def _open(self) -> None:
        """The backend's sockets and threads, opened last in ``__init__`` (none here).

        Raises:
            TransportError: they cannot be opened.
        """

    # --- names and counters ---------------------------------------------------------------

    def names_of(self, msg_type: str) -> tuple[str, ...]:
        """The type names a publisher or subscription of ``msg_type`` goes by (both spellings)."""
        return spellings(msg_type)

    def fqn(self, topic: str) -> str:
        """``topic``'s fully qualified name in this node's partition and namespace."""
        return fully_qualified_name(self.partition, self.namespace, topic)

    def count(self, name: str, amount: int = 1) -> None:
        """Add to one of the ``stats`` counters (thread-safe)."""
        with self._count_lock:
            self._counts[name] += amount

    @property
    def stats(self) -> TransportStats:
        """A snapshot of the node's counters."""
        with self._count_lock:
            counts = dict(self._counts)
        return TransportStats(**self._add_stats(counts))

    def _add_stats(self, counts: dict[str, int]) -> dict[str, int]:
        """Counters the backend keeps elsewhere, added to ``counts``."""
        return counts

    # --- topics -----------------------------------------------------------------------------

    def advertise(
        self, topic: str, msg_type: str, *, own_socket: bool = False, queue_bytes: int = 0
    ) -> Publisher:
        """Advertise ``topic`` under the spellings of ``msg_type``.

        ``own_socket``: where the backend can (ZeroMQ), the publisher sends from a socket of its
        own, announced at its own address, instead of the node's shared one; then it must be
        published from one thread at a time (a native loop's, ``native/ros_pump.py``).
        ``queue_bytes`` (above 0), for a publisher of large messages: where the backend queues
        messages for each remote subscriber by count (ZeroMQ), the publisher sends from a
        socket of its own whose queue holds only as many of the largest messages the transport
        carries as fit in ``queue_bytes`` (``zmq/hwm.py``; docs/protocol-zmq-data.md §2.8.8).

        Raises:
            LocalProtocolError: the name is not a valid Gazebo topic.
            TransportError: the node is closed.
        """
        self._check_open()
        return self._open_publisher(
            topic, self.fqn(topic), msg_type, own_socket=own_socket, queue_bytes=queue_bytes
        )

    def unadvertise(self, publisher: Publisher) -> None:
        """Withdraw ``publisher`` (called by its ``close``)."""
        if not self.closed:
            self._close_publisher(publisher)

    def publish(self, publisher: Publisher, payload: Payload, as_type: str | None = None) -> None:
        """Local subscriptions first, then one message per spelling a remote subscriber needs
        (docs/protocol-lines.md §9); ``as_type`` limits both to that spelling."""
        if as_type is None or as_type == publisher.msg_type:
            local = self._local_receivers(publisher)
            if local:
                data = payload if isinstance(payload, bytes) else bytes(payload)
                info = MessageInfo(
                    publisher.topic, publisher.msg_type, self.partition, "", intra_process=True
                )
                for sub in local:
                    sub.offer(data, info)
        for wire_type in publisher.wire_types():
            if as_type is None or wire_type == as_type:
                self._send(publisher, wire_type, payload)

    def has_connections(self, publisher: Publisher) -> bool:
        """True if a remote subscriber or a local subscription would receive a message."""
        return bool(publisher.wire_types()) or bool(self._local_receivers(publisher))

    def _local_receivers(self, publisher: Publisher) -> list[Subscription]:
        return [
            sub
            for sub in self._subscriptions.get(publisher.fqn, ())
            if not sub.ignore_local and sub.accepts(publisher.msg_type)
        ]

    def subscribe(
        self,
        topic: str,
        callback: Callback,
        msg_type: str = GENERIC_TYPE,
        *,
        ignore_local: bool = False,
        queue_size: int | None = None,
        queue_bytes: int = MAX_QUEUED_BYTES,
        copy: bool = True,
        on_delivery_start: Callable[[], None] | None = None,
        on_reject: RejectCallback | None = None,
        native: NativeLoop | None = None,
        large_messages: bool = False,
    ) -> Subscription:
        """Receive raw payloads of ``msg_type`` (either spelling; GENERIC_TYPE = any).

        ``queue_size`` None runs ``callback`` on the thread that receives (the backend's);
        N gives the subscription its own delivery thread behind a drop-oldest queue of N
        messages, which first runs ``on_delivery_start`` (e.g. to set its own priority), and
        of at most ``queue_bytes`` payload bytes (but always one message).
        ``copy=False`` hands over the backend's buffer (``bytes`` or a read-only
        ``memoryview``) instead of copying it into ``bytes``. ``on_reject(reason, detail)`` is
        told of each message of the topic the transport could not use (a malformed frame,
        another type, over ``settings.max_message_size``), on the receiving thread.
        ``native``: a loop that takes over reading a queued subscription's messages where the
        backend can hand it its socket (ZeroMQ); other backends deliver through ``callback``.
        ``large_messages``: payloads of megabytes are the topic's normal traffic (images):
        a queue that libzmq bounds in messages is sized for the largest message from the
        start (``zmq/reader.py``), not when the first large one comes, and, read on a thread
        of its own, its connections are read by a libzmq I/O thread of the large topics' own,
        at that thread's priority (``zmq/bulk_context.py``).

        Raises:
            ValueError: a queue of no messages, or ``on_delivery_start`` without a queue.
            LocalProtocolError: the name is not a valid Gazebo topic.
            TransportError: the node is closed.
        """
        if on_delivery_start is not None and queue_size is None:
            msg = "on_delivery_start needs a queue_size: without one there is no delivery thread"
            raise ValueError(msg)
        deliver = raw_deliverer(self.count, callback, copy=copy)
        return self._add_subscription(
            topic, msg_type, deliver, ignore_local, queue_size, on_delivery_start, on_reject,
            native, queue_bytes, large_messages=large_messages,
        )  # fmt: skip

    def subscribe_typed(
        self,
        topic: str,
        msg_class: type[Any],
        callback: Callback,
        *,
        msg_type: str | None = None,
        ignore_local: bool = False,
        queue_size: int | None = None,
    ) -> Subscription:
        """Like :meth:`subscribe`, decoding with ``msg_class.FromString`` (no payload copy).

        ``msg_type`` defaults to the class's full protobuf name. Undecodable payloads are
        counted in ``stats.payloads_undecodable``.
        """
        deliver = typed_deliverer(self.count, msg_class, callback)
        wanted = msg_type or msg_class.DESCRIPTOR.full_name
        return self._add_subscription(topic, wanted, deliver, ignore_local, queue_size, None, None)

    def _add_subscription(  # noqa: PLR0917 - private, called only by the two methods above
        self,
        topic: str,
        msg_type: str,
        deliver: Deliver,
        ignore_local: bool,
        queue_size: int | None,
        on_start: Callable[[], None] | None,
        on_reject: RejectCallback | None,
        native: NativeLoop | None = None,
        queue_bytes: int = MAX_QUEUED_BYTES,
        *,
        large_messages: bool = False,
    ) -> Subscription:
        self._check_open()
        sub = self.subscription_class(
            self, topic, self.fqn(topic), msg_type, deliver, ignore_local=ignore_local
        )
        sub.on_reject = on_reject
        sub.native = native
        sub.large_messages = large_messages
        if queue_size is not None:
            sub.delivery = self._open_delivery(sub, queue_size, on_start, queue_bytes)
        with self._subscriptions_lock:
            self._subscriptions[sub.fqn] = (*self._subscriptions.get(sub.fqn, ()), sub)
        try:
            self._open_subscription(sub)
        except Exception:
            sub.close()
            raise
        return sub

    def unsubscribe(self, sub: Subscription) -> None:
        """Remove ``sub`` (called by its ``close``)."""
        with self._subscriptions_lock:
            remaining = tuple(s for s in self._subscriptions.get(sub.fqn, ()) if s is not sub)
            if remaining:
                self._subscriptions[sub.fqn] = remaining
            else:
                self._subscriptions.pop(sub.fqn, None)
        if not self.closed:
            self._close_subscription(sub, last=not remaining)

    def subscriptions(self, fqn: str) -> tuple[Subscription, ...]:
        """The local subscriptions of ``fqn`` (a snapshot)."""
        return self._subscriptions.get(fqn, ())

    def _open_delivery(
        self, sub: Subscription, size: int, on_start: Callable[[], None] | None, max_bytes: int
    ) -> Delivery:
        """The queued delivery of ``sub``: by default a thread behind a drop-oldest queue."""
        return ThreadDelivery(sub, size, on_start, max_bytes)

    # --- life -------------------------------------------------------------------------------

    def _check_open(self) -> None:
        if self.closed:
            msg = "the Gazebo Transport node is closed"
            raise TransportError(msg)

    def close(self) -> None:
        """Say goodbye to peers, close every handle and release the backend; idempotent."""
        if self.closed:
            return
        self._shutdown()
        self.closed = True
        subscriptions = [sub for subs in self._subscriptions.values() for sub in subs]
        for sub in subscriptions:
            sub.close()
        self._release()

    def __enter__(self) -> Self:
        return self

    def __exit__(self, *exc_info: object) -> None:
        self.close()

    # --- the backend's hooks ------------------------------------------------------------------

    @abc.abstractmethod
    def _open_publisher(
        self, topic: str, fqn: str, msg_type: str, *, own_socket: bool = False, queue_bytes: int = 0
    ) -> Publisher:
        """Create and announce a publisher (a :class:`Publisher`, or a subclass)."""

    @abc.abstractmethod
    def _send(self, publisher: Publisher, wire_type: str, payload: Payload) -> None:
        """Send one message of ``publisher`` in the spelling ``wire_type`` to remote peers."""

    @abc.abstractmethod
    def _close_publisher(self, publisher: Publisher) -> None:
        """Withdraw ``publisher``'s announcements."""

    @abc.abstractmethod
    def _open_subscription(self, sub: Subscription) -> None:
        """Start receiving for ``sub`` (already in the table of subscriptions)."""

    @abc.abstractmethod
    def _close_subscription(self, sub: Subscription, *, last: bool) -> None:
        """Stop receiving for ``sub`` (``last``: no other local subscription of its topic)."""

    @abc.abstractmethod
    def _shutdown(self) -> None:
        """Say goodbye on the wire and stop the backend's threads; pending calls end as
        timeouts. Called once, before the handles close."""

    @abc.abstractmethod
    def _release(self) -> None:
        """Release sockets and sessions. Called once, last."""

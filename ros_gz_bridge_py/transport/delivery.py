"""Handing received payloads to callbacks: the deliverers, and the one drop-oldest queue.

A subscription created with ``queue_size=N`` keeps at most the newest N messages (and at most
:data:`MAX_QUEUED_BYTES` of them) between the network and its callback, so a slow callback
delays only its own topic and never a backend's I/O thread; when full, the oldest message is
dropped and counted, the policy of ROS "keep last N". Every backend keeps them in a
:class:`DropOldestQueue`: the ZeroMQ reader fills and drains it on its own thread
(``zmq/reader.py``), the others through a :class:`DeliveryQueue`, which drains it on a thread.
A queue that drops says so in one throttled warning (:class:`DropWarning`).
"""

from __future__ import annotations

import logging
import queue
import threading
import time
from collections.abc import Callable, Hashable
from typing import TYPE_CHECKING, Any, Generic, TypeVar, cast

from google.protobuf.message import DecodeError

if TYPE_CHECKING:
    from ros_gz_bridge_py.transport.api import MessageInfo

T = TypeVar("T")
_LOG = logging.getLogger("ros_gz_bridge_py.transport")

#: Payload bytes as a backend hands them over (bytes, or a zero-copy buffer view).
Payload = bytes | bytearray | memoryview
#: A node's counter increment, e.g. ``node.count("callback_errors")``.
Count = Callable[[str], None]
Deliver = Callable[[Payload, "MessageInfo"], None]
#: One received message waiting in a queue: its payload and what the callback is told.
Delivery = tuple[Payload, "MessageInfo"]

#: Bytes a delivery queue holds by default (at least one item is always kept): ten 1080p RGB
#: frames or two 4K RGBA ones, so a camera stream whose consumer pauses for a frame or two
#: loses nothing, while a flood of large messages costs one channel at most this much
#: (the bridge's ``max_queued_bytes`` parameter sets it; docs/configuration.md, "Node parameters").
MAX_QUEUED_BYTES = 64 * 1024 * 1024
#: Seconds between two warnings of one queue's drops.
DROP_WARN_PERIOD = 10.0


def raw_deliverer(
    count: Count, callback: Callable[[Any, MessageInfo], None], *, copy: bool = True
) -> Deliver:
    """A deliver function that hands the payload to ``callback``, counting its errors.

    With ``copy`` the payload arrives as ``bytes``; without, as the backend's buffer.
    """

    def deliver(payload: Payload, info: MessageInfo) -> None:
        try:
            callback(payload if not copy or isinstance(payload, bytes) else bytes(payload), info)
        except Exception:
            count("callback_errors")
            _LOG.exception("subscription callback for %s raised", info.topic)

    return deliver


def typed_deliverer(
    count: Count, msg_class: type[Any], callback: Callable[[Any, MessageInfo], None]
) -> Deliver:
    """A deliver function that decodes with ``msg_class`` first (no copy of the payload).

    Garbage payloads are counted as ``payloads_undecodable``, never raised.
    """

    def deliver(payload: Payload, info: MessageInfo) -> None:
        try:
            msg = msg_class.FromString(payload)
        except (DecodeError, ValueError, TypeError) as error:
            count("payloads_undecodable")
            _LOG.debug("undecodable %s payload on %s: %s", info.msg_type, info.topic, error)
            return
        try:
            callback(msg, info)
        except Exception:
            count("callback_errors")
            _LOG.exception("subscription callback for %s raised", info.topic)

    return deliver


def payload_size(item: Delivery) -> int:
    """The weight of a queued delivery: its payload's size."""
    return len(item[0])


def payload_sender(item: Delivery) -> str:
    """Who sent a queued delivery: its publisher's address ("" for this process)."""
    return item[1].publisher_address


def require_queue_size(size: int) -> None:
    """Refuse a subscription queue that could hold no message.

    Raises:
        ValueError: ``size`` is below 1.
    """
    if size < 1:
        msg = f"queue_size must be at least 1 (or None for no queue), got {size}"
        raise ValueError(msg)


class DropWarning:
    """The warning of one subscription queue that drops its oldest messages: at most one line
    per :data:`DROP_WARN_PERIOD` seconds, naming the topic, the sender whose message was
    dropped last, how many so far and the queue's bounds (one thread at a time)."""

    def __init__(self, topic: str, size: int, max_bytes: int) -> None:
        self._topic = topic
        self._size = size
        self._max_bytes = max_bytes
        self._last = -DROP_WARN_PERIOD

    def dropped(self, total: int, sender: str) -> None:
        """``total`` messages dropped so far, the last of them from ``sender``."""
        now = time.monotonic()
        if now - self._last < DROP_WARN_PERIOD:
            return
        self._last = now
        _LOG.warning(
            "%s: %d message(s) dropped so far, oldest first, the last from %s: its queue holds "
            "at most %d messages and %d bytes (parameter max_queued_bytes); they arrive "
            "faster than they are bridged",
            self._topic,
            total,
            sender or "this process",
            self._size,
            self._max_bytes,
        )


class QueueClosedError(Exception):
    """:meth:`DropOldestQueue.get` after :meth:`DropOldestQueue.close`."""


class DropOldestQueue(Generic[T]):
    """The newest ``size`` items, and no more than ``max_bytes`` of them as ``weigh`` measures
    (but always one); :meth:`put` from any thread, :meth:`get` by one consumer.

    With ``source`` (who sent an item), the bytes bound takes the oldest items of the source
    that holds the most bytes, not the oldest of all: a peer flooding a topic with large
    messages loses its own, and the other publishers' small messages between them pass (a
    rogue's 32 MB frames cost the real 50 Hz Odometry publisher 36% of its messages when any
    oldest item went). The count bound stays oldest first: it costs nothing per item.

    Built on :class:`queue.SimpleQueue`, whose put and get are single C calls: at tens of
    thousands of small messages per second a Condition-based queue costs the producer more
    than the message itself. The producer keeps the bound, taking the oldest items out when
    the queue is over it; a get racing with that can make the queue briefly hold one item more
    or fewer, never an unbounded number.
    """

    def __init__(
        self,
        size: int,
        *,
        weigh: Callable[[T], int],
        max_bytes: int = MAX_QUEUED_BYTES,
        source: Callable[[T], Hashable] | None = None,
    ) -> None:
        require_queue_size(size)
        self._size = size
        self._weigh = weigh
        self._max_bytes = max_bytes
        self._source = source
        #: One producer at a time takes every item out and puts the rest back (a put of
        #: another producer meanwhile may land before older items: the queue is ordered per
        #: producer thread, as each backend delivers a sender's messages).
        self._producing = threading.Lock()
        #: The source of the last item dropped (None before, or without ``source``).
        self.dropped_source: Hashable | None = None
        # Queued bytes = put - dropped (written by producers) - taken (by the consumer).
        self._bytes_put = self._bytes_dropped = self._bytes_taken = 0
        self._items: queue.SimpleQueue[T | object] = queue.SimpleQueue()
        #: Items dropped so far, oldest first.
        self.dropped = 0

    def put(self, item: T) -> int:
        """Queue ``item``; returns how many older items that pushed out."""
        items = self._items
        weigh = self._weigh
        self._bytes_put += weigh(item)
        items.put(item)
        dropped = 0
        if self._source is not None and self._over_budget():
            with self._producing:
                dropped = self._shed_heaviest()
        while items.qsize() > self._size or self._over_budget():
            try:
                oldest = items.get_nowait()
            except queue.Empty:  # the consumer took it first
                break
            if oldest is _CLOSED:  # never drop the end mark
                items.put(oldest)
                break
            self._bytes_dropped += weigh(cast(T, oldest))
            if self._source is not None:
                self.dropped_source = self._source(cast(T, oldest))
            dropped += 1
        self.dropped += dropped
        return dropped

    def _shed_heaviest(self) -> int:
        """Over the bytes bound: takes every item out, drops the oldest items of the heaviest
        source until the rest is within the bound (or one item is left), puts the rest back
        in order. Only on the way over the bound, so its cost is per large item."""
        assert self._source is not None
        held: list[T] = []
        closed = False
        while True:
            try:
                item = self._items.get_nowait()
            except queue.Empty:
                break
            if item is _CLOSED:
                closed = True
                continue
            held.append(cast(T, item))
        weights = [self._weigh(item) for item in held]
        sources = [self._source(item) for item in held]
        by_source: dict[Hashable, int] = {}
        for source, weight in zip(sources, weights, strict=True):
            by_source[source] = by_source.get(source, 0) + weight
        queued = sum(weights)
        gone: set[int] = set()
        while queued > self._max_bytes and len(held) - len(gone) > 1:
            heaviest = max(by_source, key=by_source.__getitem__)
            oldest = next(
                i for i, source in enumerate(sources) if source == heaviest and i not in gone
            )
            gone.add(oldest)
            by_source[heaviest] -= weights[oldest]
            queued -= weights[oldest]
            self._bytes_dropped += weights[oldest]
            self.dropped_source = heaviest
        for i, item in enumerate(held):
            if i not in gone:
                self._items.put(item)
        if closed:
            self._items.put(_CLOSED)
        return len(gone)

    def _over_budget(self) -> bool:
        queued = self._bytes_put - self._bytes_dropped - self._bytes_taken
        return queued > self._max_bytes and self._items.qsize() > 1

    def get(self, *, block: bool = True, timeout: float | None = None) -> T:
        """The oldest item; waiting (up to ``timeout`` seconds, None: for ever) if ``block``.

        Raises:
            queue.Empty: nothing is there (``block`` False) or came within ``timeout``.
            QueueClosedError: the queue was closed.
        """
        item = self._items.get(block, timeout)
        if item is _CLOSED:
            self._items.put(item)  # every later get sees it too
            raise QueueClosedError
        self._bytes_taken += self._weigh(cast(T, item))
        return cast(T, item)

    def __len__(self) -> int:
        return self._items.qsize()

    def close(self) -> None:
        """Wake the consumer: every later :meth:`get` raises :class:`QueueClosedError`."""
        self._items.put(_CLOSED)


#: The end mark :meth:`DropOldestQueue.close` puts in.
_CLOSED = object()


class DeliveryQueue(Generic[T]):
    """A :class:`DropOldestQueue` whose items ``handler`` takes on a daemon thread of its own.

    ``on_start`` runs on that thread before it takes the first item.
    """

    def __init__(
        self,
        size: int,
        handler: Callable[[T], None],
        name: str,
        *,
        weigh: Callable[[T], int],
        max_bytes: int = MAX_QUEUED_BYTES,
        source: Callable[[T], Hashable] | None = None,
        on_start: Callable[[], None] | None = None,
    ) -> None:
        self._queue: DropOldestQueue[T] = DropOldestQueue(
            size, weigh=weigh, max_bytes=max_bytes, source=source
        )
        self._handler = handler
        self._on_start = on_start
        self._closed = False
        self._thread = threading.Thread(target=self._run, name=name, daemon=True)
        self._thread.start()

    @property
    def dropped(self) -> int:
        """Items dropped so far, oldest first."""
        return self._queue.dropped

    @property
    def dropped_source(self) -> Hashable | None:
        """The source of the last item dropped (None before, or without ``source``)."""
        return self._queue.dropped_source

    def put(self, item: T) -> int:
        """Queue ``item``; returns how many older items that pushed out."""
        return self._queue.put(item)

    def close(self) -> None:
        """Stop after the item being handled; pending items are discarded. Idempotent."""
        self._closed = True
        self._queue.close()
        if self._thread is not threading.current_thread():
            self._thread.join()

    def _run(self) -> None:
        if self._on_start is not None:
            self._on_start()
        get = self._queue.get
        while True:
            try:
                item = get()
            except QueueClosedError:
                return
            if self._closed:
                return
            self._handler(item)
            del item  # a large payload is not kept while the queue waits for the next

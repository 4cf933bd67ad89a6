"""A bounded drop-oldest queue drained by its own thread.

A subscription created with ``queue_size=N`` delivers through one of these, so a slow
callback delays only its own topic and never the node's I/O thread. When the queue is full
the oldest message is dropped and counted, the same policy as ROS "keep last N".
"""

from __future__ import annotations

import logging
import queue
import threading
from collections.abc import Callable
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


def payload_size(item: tuple[Payload, MessageInfo]) -> int:
    """The weight of a queued (payload, info) delivery: its payload's size."""
    return len(item[0])


#: Bytes a delivery queue may hold (at least one item is always kept): ten 1080p frames.
MAX_QUEUED_BYTES = 64 * 1024 * 1024


def require_queue_size(size: int) -> None:
    """Refuse a subscription queue that could hold no message.

    Raises:
        ValueError: ``size`` is below 1.
    """
    if size < 1:
        msg = f"queue_size must be at least 1 (or None for no queue), got {size}"
        raise ValueError(msg)


class DeliveryQueue(Generic[T]):
    """Hands items to ``handler`` on a dedicated daemon thread, keeping the newest ``size``
    items and no more than ``max_bytes`` of them as ``weigh`` measures (but always one).

    Built on :class:`queue.SimpleQueue`, whose put and get are single C calls: at tens of
    thousands of small messages per second a Condition-based queue costs the producer (the
    node's I/O thread) more than the message itself. The bound is kept by the producer, which
    takes the oldest item out when the queue is over ``size``; a get racing with that can make
    the queue briefly hold one more or one fewer item, never an unbounded number.
    ``on_start`` runs on the delivery thread before it takes the first item.
    """

    def __init__(
        self,
        size: int,
        handler: Callable[[T], None],
        name: str,
        *,
        weigh: Callable[[T], int],
        max_bytes: int = MAX_QUEUED_BYTES,
        on_start: Callable[[], None] | None = None,
    ) -> None:
        require_queue_size(size)
        self._size = size
        self._weigh = weigh
        self._max_bytes = max_bytes
        # Queued bytes = put - dropped (written by the producer) - handled (by the consumer);
        # one writer per counter, so no lock on the hot path.
        self._bytes_put = self._bytes_dropped = self._bytes_handled = 0
        self._items: queue.SimpleQueue[T | object] = queue.SimpleQueue()
        self._handler = handler
        self._on_start = on_start
        self._closed = False
        self.dropped = 0
        self._thread = threading.Thread(target=self._run, name=name, daemon=True)
        self._thread.start()

    def put(self, item: T) -> bool:
        """Queue ``item``; False if that pushed out older ones."""
        items = self._items
        weigh = self._weigh
        self._bytes_put += weigh(item)
        items.put(item)
        kept = True
        while items.qsize() > self._size or self._over_budget():
            try:
                oldest = items.get_nowait()
            except queue.Empty:  # the delivery thread took it first
                break
            self._bytes_dropped += weigh(cast(T, oldest))
            self.dropped += 1
            kept = False
        return kept

    def _over_budget(self) -> bool:
        queued = self._bytes_put - self._bytes_dropped - self._bytes_handled
        return queued > self._max_bytes and self._items.qsize() > 1

    def close(self) -> None:
        """Stop after the item being handled; pending items are discarded. Idempotent."""
        self._closed = True
        self._items.put(_STOP)
        if self._thread is not threading.current_thread():
            self._thread.join()

    def _run(self) -> None:
        if self._on_start is not None:
            self._on_start()
        get = self._items.get
        while True:
            item = cast(T, get())  # only _STOP is not a T, and it comes after close
            if self._closed:
                return
            self._bytes_handled += self._weigh(item)
            self._handler(item)


#: Wakes the delivery thread for :meth:`DeliveryQueue.close`.
_STOP = object()

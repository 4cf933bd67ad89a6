"""A bounded drop-oldest queue drained by its own thread.

A subscription created with ``queue_size=N`` delivers through one of these, so a slow
callback delays only its own topic and never the node's I/O thread. When the queue is full
the oldest message is dropped and counted, the same policy as ROS "keep last N".
"""

from __future__ import annotations

import collections
import logging
import threading
from collections.abc import Callable
from typing import TYPE_CHECKING, Any, Generic, TypeVar

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


class DeliveryQueue(Generic[T]):
    """Hands items to ``handler`` on a dedicated daemon thread, keeping the newest ``size``."""

    def __init__(self, size: int, handler: Callable[[T], None], name: str) -> None:
        if size < 1:
            msg = f"queue_size must be at least 1 (or None for no queue), got {size}"
            raise ValueError(msg)
        self._items: collections.deque[T] = collections.deque(maxlen=size)
        self._handler = handler
        self._ready = threading.Condition()
        self._closed = False
        self.dropped = 0
        self._thread = threading.Thread(target=self._run, name=name, daemon=True)
        self._thread.start()

    def put(self, item: T) -> bool:
        """Queue ``item``; False if that pushed out the oldest one."""
        with self._ready:
            full = len(self._items) == self._items.maxlen
            if full:
                self.dropped += 1
            self._items.append(item)
            self._ready.notify()
        return not full

    def close(self) -> None:
        """Stop after the item being handled; pending items are discarded. Idempotent."""
        with self._ready:
            self._closed = True
            self._items.clear()
            self._ready.notify()
        if self._thread is not threading.current_thread():
            self._thread.join()

    def _run(self) -> None:
        while True:
            with self._ready:
                while not self._items and not self._closed:
                    self._ready.wait()
                if self._closed:
                    return
                item = self._items.popleft()
            self._handler(item)

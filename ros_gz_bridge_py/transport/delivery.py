"""A bounded drop-oldest queue drained by its own thread.

A subscription created with ``queue_size=N`` delivers through one of these, so a slow
callback delays only its own topic and never the node's I/O thread. When the queue is full
the oldest message is dropped and counted, the same policy as ROS "keep last N".
"""

from __future__ import annotations

import collections
import threading
from collections.abc import Callable
from typing import Generic, TypeVar

T = TypeVar("T")


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

"""What a :class:`~ros_gz_bridge_py.transport.node.GzNode` hands out: publishers,
subscriptions and service offers. Each closes only itself; backends subclass them to keep
their own entities (ZeroMQ records and frames, Zenoh declarations).
"""

from __future__ import annotations

import contextlib
import logging
import threading
from collections.abc import Callable
from typing import TYPE_CHECKING, Any, Protocol

from ros_gz_bridge_py.msgs.names import GENERIC_TYPE, canonical_type
from ros_gz_bridge_py.transport.api import MessageInfo, NativeLoop, RejectCallback, Rejection
from ros_gz_bridge_py.transport.delivery import (
    MAX_QUEUED_BYTES,
    Deliver,
    DeliveryQueue,
    DropWarning,
    Payload,
    payload_sender,
    payload_size,
)
from ros_gz_bridge_py.transport.wire_types import WireTypeCache

if TYPE_CHECKING:
    from ros_gz_bridge_py.transport.node import GzNode

_LOG = logging.getLogger("ros_gz_bridge_py.transport")
#: The node counter of each rejection the transport makes.
_REJECTION_COUNTERS = {
    Rejection.UNDECODABLE: "payloads_undecodable",
    Rejection.MALFORMED: "frames_malformed",
    Rejection.WRONG_TYPE: "messages_wrong_type",
    Rejection.OVERSIZE: "messages_oversize",
}


class Publisher:
    """An advertised topic; ``publish`` may be called from any thread.

    It is announced under every name in ``names`` (both spellings of its type, the configured
    one first, docs/protocol-lines.md §9) and sends each message once per spelling a remote
    subscriber needs.
    """

    def __init__(self, node: GzNode, topic: str, fqn: str, msg_type: str) -> None:
        self.topic = topic
        self.fqn = fqn
        self.msg_type = msg_type
        self.names = node.names_of(msg_type)
        self._wire_types = WireTypeCache(node.subscriber_book, fqn, self.names)
        self._node = node
        self._before_close: list[Callable[[], None]] = []
        self.closed = False

    def wire_types(self) -> frozenset[str]:
        """The spellings remote subscribers need now (empty: nobody remote listens)."""
        return self._wire_types.get()

    def watch_wire_types(self, changed: Callable[[], None]) -> Callable[[], None]:
        """Call ``changed()`` (quick, on the node's thread) whenever :meth:`wire_types` may
        have changed; returns the function that stops it."""
        return self._node.subscriber_book.watch(self.fqn, changed)

    def publish(self, msg: Any) -> None:
        """Serialize ``msg`` once and send it (see :meth:`publish_raw`)."""
        self.publish_raw(msg.SerializeToString())

    def publish_raw(self, payload: Payload, *, as_type: str | None = None) -> None:
        """Deliver to local subscriptions, and send once per spelling a remote subscriber
        needs. ``bytes`` go out without a copy; other buffers are copied once, so the caller
        may reuse them. ``as_type`` (one of ``names``) sends only that spelling, for a payload
        whose layout depends on it; local subscriptions get the one of ``msg_type``. After
        ``close`` (of this publisher or the node) it does nothing."""
        if not self.closed:
            self._node.publish(self, payload, as_type)

    def has_connections(self) -> bool:
        """True if a remote subscriber or a local subscription would receive a message."""
        return not self.closed and self._node.has_connections(self)

    def send_queue(self) -> int:
        """Messages the backend queues at most for each remote subscriber (ZeroMQ's SNDHWM);
        0 where it keeps no such queue."""
        return 0

    def before_close(self, stop: Callable[[], None]) -> Callable[[], None]:
        """Call ``stop()`` before the publisher's socket goes (its :meth:`close`, or its
        node's), e.g. to stop a native loop that sends on it; returns the function that
        cancels this."""
        self._before_close.append(stop)

        def cancel() -> None:
            with contextlib.suppress(ValueError):  # ran already
                self._before_close.remove(stop)

        return cancel

    def stop_senders(self) -> None:
        """Run what :meth:`before_close` registered (once)."""
        stops, self._before_close = self._before_close, []
        for stop in stops:
            stop()

    def close(self) -> None:
        """Unadvertise; idempotent."""
        if not self.closed:
            self.closed = True
            self.stop_senders()
            self._node.unadvertise(self)


class Delivery(Protocol):
    """How a queued subscription's messages reach its callback on a thread of their own."""

    @property
    def dropped(self) -> int: ...

    def offer(self, payload: Payload, info: MessageInfo) -> int:
        """Queue one message (from any thread); returns how many older ones it pushed out."""
        ...

    def close(self) -> None: ...


class Subscription:
    """One subscription: which types it takes, and how its messages reach ``deliver``.

    Without a queue (``delivery`` None) messages are delivered on the thread that offers
    them; with one, on the delivery's own thread. A message of its topic that the transport
    cannot use is counted on the node and told to ``on_reject`` (:meth:`reject`).
    """

    def __init__(
        self,
        node: GzNode,
        topic: str,
        fqn: str,
        msg_type: str,
        deliver: Deliver,
        *,
        ignore_local: bool,
        on_reject: RejectCallback | None = None,
    ) -> None:
        self.topic = topic
        self.fqn = fqn
        self.msg_type = msg_type
        self.names = node.names_of(msg_type)
        self.generic = msg_type == GENERIC_TYPE
        self.ignore_local = ignore_local
        self.on_reject = on_reject
        self.delivery: Delivery | None = None
        #: The loop that reads the subscription's socket natively, where the backend uses it.
        self.native: NativeLoop | None = None
        #: Whether its messages are large by nature (images, point clouds): a backend that
        #: bounds its receive queue in messages sizes it for the largest from the start.
        self.large_messages = False
        self._node = node
        self._deliver = deliver
        # (publisher id, canonical type) -> the spelling taken from that publisher.
        self._taken: dict[tuple[str, str], str] = {}
        self.closed = False

    @property
    def dropped(self) -> int:
        """Messages the bounded queue dropped (oldest first); 0 without a queue."""
        return self.delivery.dropped if self.delivery is not None else 0

    def accepts(self, msg_type: str) -> bool:
        """True if a message of ``msg_type`` is for this subscription (a spelling of its type,
        or any type for a generic subscription)."""
        return msg_type in self.names or self.generic

    def take(self, publisher: str, msg_type: str) -> bool:
        """Whether to register with ``publisher``'s announcement of ``msg_type``.

        A publisher may be announced under both spellings of its type (ours are); the first
        spelling taken from a publisher is the only one accepted from it, so a message sent
        in both spellings for different subscribers arrives here once.
        """
        if not self.accepts(msg_type):
            return False
        key = (publisher, canonical_type(msg_type))
        return self._taken.setdefault(key, msg_type) == msg_type

    def accepts_from(self, publisher: str, msg_type: str) -> bool:
        """True if a message of ``msg_type`` from ``publisher`` is for us."""
        if not self.accepts(msg_type):
            return False
        taken = self._taken.get((publisher, canonical_type(msg_type)))
        return taken is None or taken == msg_type

    def forget(self, publisher: str) -> None:
        """Forget the spellings taken from ``publisher`` (its address was disconnected)."""
        for key in [key for key in self._taken if key[0] == publisher]:
            del self._taken[key]

    def reject(self, reason: Rejection, detail: str) -> None:
        """A message of this topic could not be used: count it and tell ``on_reject`` (from
        the thread that found it; never raises)."""
        self._node.count(_REJECTION_COUNTERS.get(reason, "frames_malformed"))
        if self.on_reject is None or self.closed:
            return
        try:
            self.on_reject(reason, detail)
        except Exception:
            self._node.count("callback_errors")
            _LOG.exception("on_reject of the subscription of %s raised", self.topic)

    def offer(self, payload: Payload, info: MessageInfo) -> None:
        """Deliver now (no queue), or queue for the delivery thread."""
        if self.delivery is None:
            self.run(payload, info)
        else:
            dropped = self.delivery.offer(payload, info)
            if dropped:
                self._node.count("messages_dropped", dropped)

    def run(self, payload: Payload, info: MessageInfo) -> None:
        """Hand one message to the callback (on the delivering thread)."""
        if not self.closed:
            self._deliver(payload, info)

    def close(self) -> None:
        """Unsubscribe this subscription only; idempotent."""
        if self.closed:
            return
        self.closed = True
        self._node.unsubscribe(self)
        if self.delivery is not None:
            self.delivery.close()


class ServiceOffer:
    """An advertised service; ``key`` is what a call must match (either spelling of each type)."""

    def __init__(
        self,
        node: GzNode,
        service: str,
        fqn: str,
        types: tuple[str, str],
        handler: Callable[[bytes], tuple[bool, bytes]],
    ) -> None:
        self.service = service
        self.fqn = fqn
        self.request_type, self.response_type = types
        self.key = offer_key(fqn, *types)
        self.handler = handler
        #: The node that provides it.
        self.node = node
        self.closed = False

    def close(self) -> None:
        """Unadvertise the service; idempotent."""
        if not self.closed:
            self.closed = True
            self.node.unadvertise_service(self)


def offer_key(fqn: str, request_type: str, response_type: str) -> tuple[str, str, str]:
    """What a call must match to reach an offer (either spelling of each type)."""
    return fqn, canonical_type(request_type), canonical_type(response_type)


class ThreadDelivery:
    """A queued subscription's :class:`DeliveryQueue` (the default :class:`Delivery`)."""

    def __init__(
        self,
        sub: Subscription,
        size: int,
        on_start: Callable[[], None] | None,
        max_bytes: int = MAX_QUEUED_BYTES,
    ) -> None:
        self._queue: DeliveryQueue[tuple[Payload, MessageInfo]] = DeliveryQueue(
            size,
            lambda item: sub.run(*item),
            f"gz-sub {sub.topic}",
            weigh=payload_size,
            max_bytes=max_bytes,
            source=payload_sender,
            on_start=on_start,
        )
        self._warning = DropWarning(sub.topic, size, max_bytes)
        self._lock = threading.Lock()  # offers come from any thread

    @property
    def dropped(self) -> int:
        return self._queue.dropped

    def offer(self, payload: Payload, info: MessageInfo) -> int:
        dropped = self._queue.put((payload, info))
        if dropped:
            with self._lock:
                sender = self._queue.dropped_source
                self._warning.dropped(self._queue.dropped, str(sender) if sender else "")
        return dropped

    def close(self) -> None:
        self._queue.close()

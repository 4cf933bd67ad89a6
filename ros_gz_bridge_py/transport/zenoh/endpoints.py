"""The handles a :class:`~ros_gz_bridge_py.transport.zenoh.node.ZenohNode` gives out.

Each handle owns its Zenoh entities (publisher, subscriber or queryable) and its liveliness
token, and undeclares exactly those when closed, so closing one never affects another.
"""

from __future__ import annotations

import contextlib
import logging
from collections.abc import Callable
from typing import TYPE_CHECKING, Any

import zenoh

from ros_gz_bridge_py.msgs.names import GENERIC_TYPE, spellings
from ros_gz_bridge_py.transport.api import MessageInfo, Publisher, ServiceOffer, Subscription
from ros_gz_bridge_py.transport.delivery import Deliver, DeliveryQueue, payload_size
from ros_gz_bridge_py.transport.wire_types import WireTypeCache

if TYPE_CHECKING:
    from ros_gz_bridge_py.transport.zenoh.node import ZenohNode

_LOG = logging.getLogger("ros_gz_bridge_py.transport")

#: One received message: the payload and what the callback learns about it.
Delivery = tuple[bytes, MessageInfo]
#: Hands one message to the user, guarding against (and counting) its errors.


def undeclare(*entities: Any) -> None:
    """Undeclare Zenoh entities, ignoring those already gone with a closed session."""
    for entity in entities:
        with contextlib.suppress(zenoh.ZError):
            entity.undeclare()


class ZenohPublisher(Publisher):
    """An advertised topic: a Zenoh publisher on the FQN plus its MP token."""

    def __init__(
        self,
        node: ZenohNode,
        topic: str,
        fqn: str,
        msg_type: str,
        entities: tuple[zenoh.Publisher, zenoh.LivelinessToken],
    ) -> None:
        self.topic = topic
        self.fqn = fqn
        self.msg_type = msg_type
        self.names = spellings(msg_type)
        #: The attachment of a put in each spelling: the type name as raw bytes (§4.5).
        self.attachments = {name: name.encode() for name in self.names}
        self.zenoh_publisher, self._token = entities
        self._wire_types = WireTypeCache(node.subscriber_book, fqn, self.names)
        self._node = node
        self._closed = False

    def wire_types(self) -> frozenset[str]:
        """The spellings remote subscribers (MS tokens) need now."""
        return self._wire_types.get()

    def publish(self, msg: Any) -> None:
        """Serialize ``msg`` once and send it (see :meth:`publish_raw`)."""
        self.publish_raw(msg.SerializeToString())

    def publish_raw(
        self, payload: bytes | bytearray | memoryview, *, as_type: str | None = None
    ) -> None:
        """Deliver to local subscriptions, and put on Zenoh once per spelling a remote MS token
        needs (``as_type``: only that spelling). After ``close`` it does nothing."""
        if not self._closed:
            self._node.publish(self, payload, as_type)

    def has_connections(self) -> bool:
        """True if a remote MS token or a local subscription matches."""
        return not self._closed and self._node.has_connections(self)

    def close(self) -> None:
        """Undeclare the MP token and the Zenoh publisher; idempotent."""
        if not self._closed:
            self._closed = True
            self._node.forget_publisher(self)
            undeclare(self._token, self.zenoh_publisher)


class ZenohSubscription(Subscription):
    """One subscription: its Zenoh subscriber, MS token, type rule and optional queue."""

    def __init__(
        self,
        node: ZenohNode,
        topic: str,
        fqn: str,
        msg_type: str,
        deliver: Deliver,
        *,
        ignore_local: bool,
        queue_size: int | None,
        on_delivery_start: Callable[[], None] | None,
    ) -> None:
        self.topic = topic
        self.fqn = fqn
        self.msg_type = msg_type
        self.names = spellings(msg_type)
        self.generic = msg_type == GENERIC_TYPE
        self.ignore_local = ignore_local
        #: The Zenoh subscriber and MS token, in declaration order.
        self.entities: list[Any] = []
        self._node = node
        self._deliver = deliver
        self._closed = False
        self._queue: DeliveryQueue[Delivery] | None = None
        if queue_size is not None:
            self._queue = DeliveryQueue(
                queue_size,
                self._run,
                f"gz-sub {topic}",
                weigh=payload_size,
                on_start=on_delivery_start,
            )

    @property
    def dropped(self) -> int:
        """Messages the bounded queue dropped (oldest first)."""
        return self._queue.dropped if self._queue is not None else 0

    def accepts(self, msg_type: str) -> bool:
        """True if a message of ``msg_type`` is for this subscription (either spelling of
        its type, or any type for a generic subscription)."""
        return msg_type in self.names or self.generic

    def offer(self, payload: bytes, info: MessageInfo) -> None:
        """Deliver now, or queue for the delivery thread."""
        if self._queue is None:
            self._run((payload, info))
        elif not self._queue.put((payload, info)):
            self._node.count("messages_dropped")

    def _run(self, item: Delivery) -> None:
        if not self._closed:
            self._deliver(*item)

    def close(self) -> None:
        """Undeclare the MS token and the Zenoh subscriber of this subscription; idempotent."""
        if self._closed:
            return
        self._closed = True
        self._node.forget_subscription(self)
        undeclare(*reversed(self.entities))
        if self._queue is not None:
            self._queue.close()


class ZenohServiceOffer(ServiceOffer):
    """An advertised service: a queryable on the service FQN plus its SS token."""

    def __init__(
        self,
        node: ZenohNode,
        service: str,
        key: tuple[str, str, str],
        handler: Callable[[bytes], tuple[bool, bytes]],
    ) -> None:
        self.service = service
        #: (service FQN, request type, response type): what a local call must match.
        self.key = key
        self.handler = handler
        #: The queryable and SS token, in declaration order.
        self.entities: list[Any] = []
        self._node = node
        self._closed = False

    def close(self) -> None:
        """Undeclare the SS token and the queryable; idempotent."""
        if not self._closed:
            self._closed = True
            self._node.forget_offer(self)
            undeclare(*reversed(self.entities))

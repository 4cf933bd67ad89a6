"""The handles a :class:`~ros_gz_bridge_py.transport.zmq_node.ZmqNode` gives out.

Each handle keeps what it needs to do its job without registry lookups (the precomputed
FQN, the type matching rule, the decoder) and closes only itself.
"""

from __future__ import annotations

import logging
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from ros_gz_bridge_py.msgs import GENERIC_TYPE
from ros_gz_bridge_py.transport.api import MessageInfo, Publisher, ServiceOffer, Subscription
from ros_gz_bridge_py.transport.wire import Frame, PublisherRecord, encode_data

if TYPE_CHECKING:
    from ros_gz_bridge_py.transport.zmq_node import ZmqNode
    from ros_gz_bridge_py.transport.zmq_reader import SubscriptionReader

_LOG = logging.getLogger("ros_gz_bridge_py.transport")


class ZmqPublisher(Publisher):
    """An advertised topic of a :class:`ZmqNode`; ``publish`` may be called from any thread."""

    def __init__(self, node: ZmqNode, topic: str, msg_type: str, record: PublisherRecord) -> None:
        self.topic = topic
        self.msg_type = msg_type
        self.fqn = record.topic
        self.record = record
        #: The data frames with an empty payload, encoded once (§2.8.1).
        self.wire_frames = encode_data(record.topic, record.address, b"", msg_type)
        self._node = node
        self._closed = False

    def publish(self, msg: Any) -> None:
        """Serialize ``msg`` once and send it (see :meth:`publish_raw`)."""
        self.publish_raw(msg.SerializeToString())

    def publish_raw(self, payload: bytes | bytearray | memoryview) -> None:
        """Deliver to local subscriptions, and on the wire if a remote subscriber matches.

        ``bytes`` payloads are sent without a copy; other buffers are copied once so the
        caller may reuse them. After ``close`` (of this publisher or the node) it does nothing.
        """
        if not self._closed:
            self._node.publish(self, payload)

    def has_connections(self) -> bool:
        """True if a remote subscriber (NEW_CONNECTION) or a local subscription matches."""
        return not self._closed and self._node.has_connections(self)

    def close(self) -> None:
        """Unadvertise; idempotent."""
        if not self._closed:
            self._closed = True
            self._node.unadvertise(self)


class ZmqSubscription(Subscription):
    """One subscription: matching rule, decoder and, with a queue, its own reader (a SUB
    socket and thread, :mod:`~.zmq_reader`)."""

    def __init__(
        self,
        node: ZmqNode,
        topic: str,
        fqn: str,
        msg_type: str,
        deliver: Callable[[Frame, MessageInfo], None],
        *,
        ignore_local: bool,
        queue_size: int | None,
        on_delivery_start: Callable[[], None] | None,
    ) -> None:
        self.topic = topic
        self.fqn = fqn
        self.msg_type = msg_type
        self.ignore_local = ignore_local
        self.record: PublisherRecord | None = None
        self._node = node
        self._deliver = deliver
        self._closed = False
        self.reader: SubscriptionReader | None = None
        if queue_size is not None:
            self.reader = node.new_reader(
                fqn, self.accepts, self._run, queue_size, on_delivery_start
            )

    @property
    def dropped(self) -> int:
        """Messages the bounded queue dropped (oldest first)."""
        return self.reader.dropped if self.reader is not None else 0

    def accepts(self, msg_type: str) -> bool:
        """True if a message of ``msg_type`` is for this subscription (exact or generic)."""
        return self.msg_type in (GENERIC_TYPE, msg_type)

    def offer(self, payload: Frame, info: MessageInfo) -> None:
        """Deliver now, or hand to the reader's thread (an intra-process message)."""
        if self.reader is None:
            self._run(payload, info)
        else:
            self.reader.offer_local(bytes(payload), info)

    def _run(self, payload: Frame, info: MessageInfo) -> None:
        if not self._closed:
            self._deliver(payload, info)

    def close(self) -> None:
        """Unsubscribe this subscription only; idempotent."""
        if self._closed:
            return
        self._closed = True
        self._node.unsubscribe(self)
        if self.reader is not None:
            self.reader.close()


@dataclass(eq=False)
class ZmqServiceOffer(ServiceOffer):
    """An advertised service of a :class:`ZmqNode`."""

    node: ZmqNode
    record: PublisherRecord
    handler: Callable[[bytes], tuple[bool, bytes]]
    #: (service FQN, request type, response type): what a request must match exactly.
    key: tuple[str, str, str]
    closed: bool = False

    def close(self) -> None:
        """Unadvertise the service; idempotent."""
        if not self.closed:
            self.closed = True
            self.node.unadvertise_service(self)

"""The handles a :class:`~ros_gz_bridge_py.transport.zmq.node.ZmqNode` gives out.

Each handle keeps what it needs to do its job without registry lookups (the precomputed
FQN, the type matching rule, the decoder) and closes only itself.
"""

from __future__ import annotations

import logging
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from ros_gz_bridge_py.msgs.names import GENERIC_TYPE, canonical_type, spellings
from ros_gz_bridge_py.transport.api import MessageInfo, Publisher, ServiceOffer, Subscription
from ros_gz_bridge_py.transport.wire_types import WireTypeCache
from ros_gz_bridge_py.transport.zmq.wire import Frame, PublisherRecord, encode_data

if TYPE_CHECKING:
    from ros_gz_bridge_py.transport.zmq.node import ZmqNode
    from ros_gz_bridge_py.transport.zmq.reader import SubscriptionReader

_LOG = logging.getLogger("ros_gz_bridge_py.transport")


class ZmqPublisher(Publisher):
    """An advertised topic of a :class:`ZmqNode`; ``publish`` may be called from any thread.

    It is announced once per spelling of its type (``records``, the configured one first), so
    typed subscribers of every Gazebo line take it (docs/protocol.md §9).
    """

    def __init__(
        self,
        node: ZmqNode,
        topic: str,
        msg_type: str,
        records: tuple[PublisherRecord, ...],
        wire_types: WireTypeCache,
    ) -> None:
        self.topic = topic
        self.msg_type = msg_type
        self.names = spellings(msg_type)
        self.fqn = records[0].topic
        self.records = records
        #: The data frames with an empty payload per spelling, encoded once (§2.8.1).
        self.wire_frames = {
            record.msg_type: encode_data(record.topic, record.address, b"", record.msg_type)
            for record in records
        }
        self._wire_types = wire_types
        self._node = node
        self._closed = False

    def wire_types(self) -> frozenset[str]:
        """The spellings remote subscribers need now (empty: nobody remote listens)."""
        return self._wire_types.get()

    def publish(self, msg: Any) -> None:
        """Serialize ``msg`` once and send it (see :meth:`publish_raw`)."""
        self.publish_raw(msg.SerializeToString())

    def publish_raw(
        self, payload: bytes | bytearray | memoryview, *, as_type: str | None = None
    ) -> None:
        """Deliver to local subscriptions, and on the wire if a remote subscriber matches.

        ``bytes`` payloads are sent without a copy; other buffers are copied once so the
        caller may reuse them. After ``close`` (of this publisher or the node) it does nothing.
        ``as_type`` (one of ``names``) sends only that spelling, for a payload whose layout
        depends on the spelling; local subscriptions get the one of ``msg_type``.
        """
        if not self._closed:
            self._node.publish(self, payload, as_type)

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
        self.names = spellings(msg_type)
        self.generic = msg_type == GENERIC_TYPE
        self.ignore_local = ignore_local
        self.record: PublisherRecord | None = None
        # (publisher address, canonical type) -> the spelling taken from it (I/O thread writes).
        self._taken: dict[tuple[str, str], str] = {}
        self._node = node
        self._deliver = deliver
        self._closed = False
        self.reader: SubscriptionReader | None = None
        if queue_size is not None:
            self.reader = node.new_reader(
                fqn, self.accepts_from, self._run, queue_size, on_delivery_start
            )

    @property
    def dropped(self) -> int:
        """Messages the bounded queue dropped (oldest first)."""
        return self.reader.dropped if self.reader is not None else 0

    def accepts(self, msg_type: str) -> bool:
        """True if a message of ``msg_type`` is for this subscription (either spelling of
        its type, or any type for a generic subscription)."""
        return msg_type in self.names or self.generic

    def take(self, record: PublisherRecord) -> bool:
        """Whether to register (NEW_CONNECTION) with the publisher announced by ``record``.

        A publisher may be announced under both spellings of its type at one address (ours
        are); the first spelling taken from an address is the only one accepted from it, so
        a message sent in both spellings for different subscribers arrives here once.
        """
        if not self.accepts(record.msg_type):
            return False
        key = (record.address, canonical_type(record.msg_type))
        return self._taken.setdefault(key, record.msg_type) == record.msg_type

    def accepts_from(self, sender: str, msg_type: str) -> bool:
        """True if a message of ``msg_type`` from the publisher at ``sender`` is for us."""
        if not self.accepts(msg_type):
            return False
        taken = self._taken.get((sender, canonical_type(msg_type)))
        return taken is None or taken == msg_type

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

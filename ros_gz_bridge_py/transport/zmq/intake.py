"""Where a ZeroMQ node's data comes in: the shared SUB socket and the queued subscriptions'
readers (the native channels of small messages through a SUB socket of their own, which they
share: ``shared_sub.py``), connected to publishers as discovery learns them and disconnected
when they go.

§2.8.1 step 4 connects a SUB socket once per publisher address. We also disconnect: when
the last remote record at an address goes away for a topic (UNADVERTISE, BYE, a process
silent for 3 s, docs/protocol-zmq-discovery.md §2.5), the readers of that topic disconnect from it,
and the shared socket does once no record at all is left there, each a moment later
(``connections.LEAVE_AFTER``), so that what the publisher sent last still arrives. gz never
disconnects; without it, addresses of a peer that is gone are retried for ever
(docs/protocol-zmq-data.md §2.8.7). Everything here runs on the I/O thread; readers do their part on
their own threads. The readers of large messages on threads of their own have a ZeroMQ context
of their own (``bulk_context.py``).
"""

from __future__ import annotations

import logging
from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING, cast

from ros_gz_bridge_py.transport.api import NativeLoop
from ros_gz_bridge_py.transport.handles import Subscription
from ros_gz_bridge_py.transport.throttle import Throttle
from ros_gz_bridge_py.transport.zmq.bulk_context import BulkContext
from ros_gz_bridge_py.transport.zmq.connections import SubConnections
from ros_gz_bridge_py.transport.zmq.reader import NativeReader, SubscriptionReader
from ros_gz_bridge_py.transport.zmq.shared_sub import SharedSub
from ros_gz_bridge_py.transport.zmq.socket_owner import Topic
from ros_gz_bridge_py.transport.zmq.sockets import NodeSockets
from ros_gz_bridge_py.transport.zmq.wire import PublisherRecord

if TYPE_CHECKING:
    from ros_gz_bridge_py.transport.zmq.node import ZmqGzNode

_LOG = logging.getLogger("ros_gz_bridge_py.transport")
#: A queued subscription's reader, whichever drives it.
Reader = SubscriptionReader | NativeReader
#: Seconds between two warnings about refused messages on the shared SUB socket.
WARN_PERIOD = 5.0


class DataIntake:
    """The node's SUB connections and readers (I/O thread, except :meth:`open_reader`)."""

    def __init__(
        self, node: ZmqGzNode, sockets: NodeSockets, drain_shared: Callable[[], None]
    ) -> None:
        self._node = node
        self._context = sockets.context
        self.readers: list[Reader] = []
        self.shared = SubConnections(
            sockets.sub,
            drain=drain_shared,
            on_refused=self._refused_shared,
            count=node.count,
            what="the node's SUB socket",
        )
        self._warning = Throttle(WARN_PERIOD)
        self._native_sub: SharedSub | None = None
        self._bulk: BulkContext | None = None

    @property
    def received(self) -> int:
        """Messages the readers accepted."""
        return sum(reader.received for reader in self.readers)

    def open_reader(
        self, sub: Subscription, size: int, on_start: Callable[[], None] | None, max_bytes: int
    ) -> Reader:
        """A queued subscription's reader: its own SUB socket, read on a thread of its own
        or, where a native loop reads it (``sub.native``), on that loop's, shared with the
        node's other native channels unless its messages are large by nature (``reader.py``)."""
        node = self._node
        topic = Topic(
            sub.fqn, node.partition, sub.accepts_from, sub.accepts, sub.reject, node.settings,
            node.count, max_bytes, sub.large_messages,
        )  # fmt: skip
        native = sub.native
        if native is not None:
            shared = None if sub.large_messages else self._shared_sub(native)
            reader: Reader = NativeReader(
                self._context, topic, deliver=sub.run, size=size, native=native, shared=shared
            )
        else:
            context, start = self._context, on_start
            if sub.large_messages:  # its frames read by an I/O thread of their own
                bulk = self._bulk_context()
                context, start = bulk.context, bulk.following(on_start)
            reader = SubscriptionReader(context, topic, deliver=sub.run, size=size, on_start=start)
        self.readers.append(reader)
        return reader

    def _bulk_context(self) -> BulkContext:
        """The context of the large-message readers, made with the first."""
        if self._bulk is None:
            self._bulk = BulkContext()
        return self._bulk

    def _shared_sub(self, native: NativeLoop) -> SharedSub:
        """The socket the native channels of small messages share, made with the first."""
        if self._native_sub is None:
            node = self._node
            self._native_sub = SharedSub(self._context, node.settings, node.count, native)
        return self._native_sub

    def close(self) -> None:
        """The native channels' shared socket and the large-message readers' context go
        (before the node's context)."""
        if self._native_sub is not None:
            self._native_sub.close()
        if self._bulk is not None:
            self._bulk.close()

    def close_reader(self, reader: Reader) -> None:
        if reader in self.readers:
            self.readers.remove(reader)

    def connect(self, record: PublisherRecord, subs: Sequence[Subscription]) -> bool:
        """§2.8.1 step 4: connect to ``record``'s address, the shared socket once per address
        and each queued subscription's reader; False if the address cannot be connected."""
        for sub in subs:
            if sub.delivery is not None:
                cast(Reader, sub.delivery).connect(record.address)
        if any(s.delivery is None for s in subs):
            return self.shared.connect(record.address)
        return True

    def publisher_gone(self, record: PublisherRecord, remaining: Sequence[PublisherRecord]) -> None:
        """``record`` went away; ``remaining`` are the remote records still known (all topics).

        Readers of its topic leave the address when no record of the topic is left there; the
        shared socket when no record at all is.
        """
        address = record.address
        if any(r.address == address and r.topic == record.topic for r in remaining):
            return
        for sub in self._node.subscriptions(record.topic):
            sub.forget(address)
            if sub.delivery is not None:
                cast(Reader, sub.delivery).leave(address)
        if address in self.shared.connected and not any(r.address == address for r in remaining):
            self.shared.leave(address)

    def _refused_shared(self, address: str) -> None:
        """A message refused on the shared socket: its topic is unknown, so the node counts it."""
        self._node.count("messages_oversize")
        if self._warning.ready():
            _LOG.warning(
                "dropped a message from %s larger than %d bytes (GZ_TRANSPORT_MAX_MESSAGE_SIZE) "
                "or not in ZeroMQ framing; raise the limit if the publisher is legitimate",
                address,
                self._node.settings.max_message_size,
            )

"""The handles of the ZeroMQ backend: what each keeps besides the shared handle.

A publisher keeps its discovery records (one per spelling) and its data frames encoded once;
a subscription its record for SUBSCRIBERS_REP answers and, with a queue, its reader (its own
SUB socket and thread, ``zmq/reader.py``); a service offer its record.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING, Any

from ros_gz_bridge_py.transport.delivery import Payload
from ros_gz_bridge_py.transport.handles import Publisher, ServiceOffer, Subscription
from ros_gz_bridge_py.transport.zmq.wire import Frame, PublisherRecord, encode_data

if TYPE_CHECKING:
    from ros_gz_bridge_py.transport.zmq.node import ZmqGzNode


class ZmqPublisher(Publisher):
    """Announced once per spelling of its type (``records``, the configured one first), from
    the node's PUB address (docs/protocol-lines.md §9), or from the address of a PUB socket of its
    own (``sock``)."""

    def __init__(
        self,
        node: ZmqGzNode,
        topic: str,
        fqn: str,
        msg_type: str,
        records: tuple[PublisherRecord, ...],
        *,
        sock: Any = None,
        send_queue: int = 0,
    ) -> None:
        super().__init__(node, topic, fqn, msg_type)
        self.records = records
        #: Its own PUB socket, or None (the node's).
        self.sock = sock
        #: Where a native loop sends on that socket: how Python's sends go too, so that the
        #: socket is used by one thread at a time (``sender(type frame, payload)``,
        #: ``native/ros_pump.py``); None: on the socket, from the publishing thread.
        self.sender: Callable[[Frame, Payload], object] | None = None
        self._send_queue = send_queue
        #: The data frames with an empty payload per spelling, encoded once (§2.8.2).
        self.wire_frames: dict[str, list[Frame]] = {
            record.msg_type: encode_data(record.topic, record.address, b"", record.msg_type)
            for record in records
        }

    def send_queue(self) -> int:
        """The SNDHWM of its socket, set when the socket was made (docs/protocol-zmq-data.md
        §2.8.8)."""
        return self._send_queue


class ZmqSubscription(Subscription):
    """A subscription with its record (announced in SUBSCRIBERS_REP answers,
    docs/protocol-zmq-discovery.md §2.4), set when the node opens it."""

    record: PublisherRecord | None = None

    def reads_own_socket(self) -> bool:
        """True for a queued subscription: its reader has a SUB socket of its own."""
        return self.delivery is not None


class ZmqServiceOffer(ServiceOffer):
    """An advertised service and its discovery record."""

    def __init__(
        self,
        node: ZmqGzNode,
        service: str,
        record: PublisherRecord,
        types: tuple[str, str],
        handler: Callable[[bytes], tuple[bool, bytes]],
    ) -> None:
        super().__init__(node, service, record.topic, types, handler)
        self.record = record

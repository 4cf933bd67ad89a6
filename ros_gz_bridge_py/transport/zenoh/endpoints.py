"""The handles of the Zenoh backend: each owns its Zenoh entities (publisher, subscriber or
queryable) and its liveliness tokens, and undeclares exactly those when closed."""

from __future__ import annotations

import contextlib
from collections.abc import Callable
from typing import TYPE_CHECKING, Any

import zenoh

from ros_gz_bridge_py.transport.api import MessageInfo, Rejection
from ros_gz_bridge_py.transport.handles import Publisher, ServiceOffer, Subscription
from ros_gz_bridge_py.transport.names import decompose

if TYPE_CHECKING:
    from ros_gz_bridge_py.transport.zenoh.node import ZenohGzNode
    from ros_gz_bridge_py.transport.zenoh.node_services import ZenohServices


def undeclare(*entities: Any) -> None:
    """Undeclare Zenoh entities, ignoring those already gone with a closed session."""
    for entity in entities:
        with contextlib.suppress(zenoh.ZError):
            entity.undeclare()


class ZenohPublisher(Publisher):
    """A Zenoh publisher on the topic's FQN plus its MP token."""

    def __init__(self, node: ZenohGzNode, topic: str, fqn: str, msg_type: str) -> None:
        super().__init__(node, topic, fqn, msg_type)
        #: The attachment of a put in each spelling: the type name as raw bytes
        #: (docs/protocol-zenoh.md §4.5).
        self.attachments = {name: name.encode() for name in self.names}
        #: The Zenoh publisher and the MP token, in declaration order.
        self.entities: list[Any] = []


class ZenohSubscription(Subscription):
    """A subscription and its Zenoh subscriber and MS token."""

    #: The Zenoh subscriber and MS token, in declaration order (set when the node opens it).
    entities: list[Any]


class ZenohServiceOffer(ServiceOffer):
    """A queryable on the service FQN plus its SS token."""

    def __init__(
        self,
        node: ZenohServices,
        service: str,
        fqn: str,
        types: tuple[str, str],
        handler: Callable[[bytes], tuple[bool, bytes]],
    ) -> None:
        super().__init__(node, service, fqn, types, handler)
        #: The queryable and SS token, in declaration order.
        self.entities: list[Any] = []


def take_sample(
    sub: Subscription, sample: zenoh.Sample, partition: str, limit: int
) -> tuple[bytes, MessageInfo] | None:
    """A remote sample's payload and info as gz checks it (docs/protocol-zenoh.md §4.5), or None
    once ``sub`` was told why not: no or an unreadable type attachment, another type, or a
    payload over ``limit`` bytes (Zenoh itself drops larger fragmented messages unseen,
    ``config.limit_message_size``)."""
    attachment = sample.attachment
    if attachment is None:
        sub.reject(Rejection.MALFORMED, "a sample without the type attachment")
        return None
    try:
        msg_type = attachment.to_bytes().decode()
    except UnicodeDecodeError:
        sub.reject(Rejection.MALFORMED, "a sample whose type attachment is not UTF-8")
        return None
    if not sub.accepts(msg_type):
        sub.reject(Rejection.WRONG_TYPE, f"a sample of type {msg_type}")
        return None
    size = len(sample.payload)
    if size > limit:
        sub.reject(
            Rejection.OVERSIZE,
            f"a sample of {size} bytes, over {limit} (GZ_TRANSPORT_MAX_MESSAGE_SIZE)",
        )
        return None
    name = (decompose(sub.fqn) or ("", sub.topic))[1]
    return sample.payload.to_bytes(), MessageInfo(name, msg_type, partition, "", False)

"""The handles of the Zenoh backend: each owns its Zenoh entities (publisher, subscriber or
queryable) and its liveliness tokens, and undeclares exactly those when closed."""

from __future__ import annotations

import contextlib
from collections.abc import Callable
from typing import TYPE_CHECKING, Any

import zenoh

from ros_gz_bridge_py.transport.delivery import Deliver
from ros_gz_bridge_py.transport.handles import Publisher, ServiceOffer, Subscription

if TYPE_CHECKING:
    from ros_gz_bridge_py.transport.zenoh.node import ZenohGzNode


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
        #: (docs/protocol.md §4.5).
        self.attachments = {name: name.encode() for name in self.names}
        #: The Zenoh publisher and the MP token, in declaration order.
        self.entities: list[Any] = []


class ZenohSubscription(Subscription):
    """A subscription and its Zenoh subscriber and MS token."""

    def __init__(
        self,
        node: ZenohGzNode,
        topic: str,
        fqn: str,
        msg_type: str,
        deliver: Deliver,
        *,
        ignore_local: bool,
    ) -> None:
        super().__init__(node, topic, fqn, msg_type, deliver, ignore_local=ignore_local)
        #: The Zenoh subscriber and MS token, in declaration order.
        self.entities: list[Any] = []


class ZenohServiceOffer(ServiceOffer):
    """A queryable on the service FQN plus its SS token."""

    def __init__(
        self,
        node: ZenohGzNode,
        service: str,
        fqn: str,
        types: tuple[str, str],
        handler: Callable[[bytes], tuple[bool, bytes]],
    ) -> None:
        super().__init__(node, service, fqn, types, handler)
        #: The queryable and SS token, in declaration order.
        self.entities: list[Any] = []

"""The Zenoh Gazebo Transport node of gz-transport 15 (Jetty), docs/protocol-zenoh.md §4.

Each :class:`ZenohGzNode` opens its own Zenoh session and looks like one gz process (own
process and node UUIDs). Topics and services are Zenoh keys equal to their fully qualified
name; the message type travels as the sample attachment; the graph is the set of ``@gz/…``
tokens (MP publishers, MS subscriptions, SS services) a liveliness subscriber with history sees.

As in gz: a publisher puts only while some *other* process holds an MS token for its topic
with its type or ``google.protobuf.Message`` (gating); a service call is sent only once an
SS token with its types is known, a provider whose handler fails sends no reply, and a query
that completes without a reply is reported as a failure (a timeout if the deadline passed
first). Local subscriptions get our own messages from the shared publish; Zenoh's own
session-local loop-back is switched off (publishers put to remote sessions only, subscribers
take remote samples only), so nothing is delivered twice (gz-transport #961). Every Zenoh
peer is Jetty or later, so our tokens say ``gz.msgs`` (docs/protocol-lines.md §9.3). Offers and
calls are the node's service half, :class:`~.node_services.ZenohServices`.

Threads: Zenoh runs callbacks on threads of its own (one per subscription, queryable, the
liveliness subscriber and each pending call); subscription callbacks without a queue and
service handlers run there. One node thread (``gz-zenoh``) starts local service calls and ends
calls whose deadline passed; a ``request_async`` callback runs once, on it or on the reply's
Zenoh thread. Bad network input never raises out of a Zenoh callback: liveliness samples count
as ``datagrams_received`` (``datagrams_malformed`` when gz would reject the token), a sample
without a readable attachment as ``frames_malformed``, one of a type not taken as
``messages_wrong_type``, one over the size limit as ``messages_oversize`` (each also told to
the subscription's ``on_reject``).
"""

from __future__ import annotations

import contextlib
import logging
import re
import threading
from typing import Any, ClassVar, cast

import zenoh

from ros_gz_bridge_py.errors import LocalProtocolError, TransportError
from ros_gz_bridge_py.msgs.names import Spelling, canonical_type
from ros_gz_bridge_py.transport.api import GraphEndpoint, TopicInfo
from ros_gz_bridge_py.transport.delivery import Payload
from ros_gz_bridge_py.transport.handles import Publisher, ServiceOffer, Subscription
from ros_gz_bridge_py.transport.names import decompose
from ros_gz_bridge_py.transport.settings import TransportSettings
from ros_gz_bridge_py.transport.zenoh.config import (
    Overrides,
    describe_session,
    limit_message_size,
    session_config,
)
from ros_gz_bridge_py.transport.zenoh.endpoints import (
    ZenohPublisher,
    ZenohSubscription,
    take_sample,
    undeclare,
)
from ros_gz_bridge_py.transport.zenoh.graph import ZenohGraph
from ros_gz_bridge_py.transport.zenoh.keys import (
    GRAPH_KEY,
    EntityKind,
    GraphToken,
    message_token,
    parse_token,
)
from ros_gz_bridge_py.transport.zenoh.node_services import ZenohCall, ZenohServices

_LOG = logging.getLogger("ros_gz_bridge_py.transport")
#: Where in zenoh's Rust sources an error was raised (" at /root/.cargo/.../orchestrator.rs:447").
_SOURCE_LOCATION = re.compile(r"\s+at \S+\.rs:\d+")


class ZenohGzNode(ZenohServices):
    """A Gazebo Transport node speaking gz-transport 15's Zenoh protocol."""

    default_peer_spelling: ClassVar[Spelling | None] = Spelling.GZ
    subscription_class = ZenohSubscription

    def __init__(
        self,
        partition: str | None = None,
        namespace: str = "",
        settings: TransportSettings | None = None,
        *,
        config: zenoh.Config | None = None,
        config_overrides: Overrides | None = None,
    ) -> None:
        """Open the session (see :mod:`.config` for ``config`` and ``config_overrides``).

        Raises:
            LocalProtocolError: the partition or namespace is invalid or the partition empty.
            TransportError: the Zenoh session cannot be opened (e.g. no router in client mode).
        """
        super().__init__(partition, namespace, settings)
        self._start_services()
        if not self.partition:
            msg = (
                "the Zenoh backend needs a non-empty partition (an empty one gives invalid "
                "liveliness tokens); set GZ_PARTITION or the node's partition"
            )
            raise LocalProtocolError(msg)
        self._graph = ZenohGraph(self.process_uuid)
        self._publishers: set[Publisher] = set()
        chosen = limit_message_size(
            session_config(config, config_overrides), self.settings.max_message_size
        )
        self._where = describe_session(chosen)
        try:
            self._session = zenoh.open(chosen)
        except zenoh.ZError as error:
            reason = _SOURCE_LOCATION.sub("", str(error)).rstrip(". ")
            msg = (
                f"cannot open the Zenoh session ({self._where}): {reason}; start the router it "
                "connects to, or set its endpoints (ZENOH_CONFIG, "
                "GZ_TRANSPORT_ZENOH_CONFIG_OVERRIDE; docs/zenoh.md)"
            )
            raise TransportError(msg) from error
        self._thread = threading.Thread(target=self._node_main, name="gz-zenoh", daemon=True)
        self._thread.start()
        self._graph_subscriber = self._session.liveliness().declare_subscriber(
            GRAPH_KEY, self._on_token, history=True
        )

    @property
    def session(self) -> zenoh.Session:
        """The node's Zenoh session (for tools and tests that need raw Zenoh access)."""
        return self._session

    # --- topics -----------------------------------------------------------------------------

    def _open_publisher(
        self, topic: str, fqn: str, msg_type: str, *, own_socket: bool = False, queue_bytes: int = 0
    ) -> Publisher:
        """A Zenoh publisher on the FQN (remote destinations only) and its MP token;
        ``own_socket`` and ``queue_bytes`` change nothing here (ZeroMQ notions; Zenoh's
        publishers drop what the network cannot take, docs/protocol-zenoh.md §4.2)."""
        publisher = ZenohPublisher(self, topic, fqn, msg_type)
        token = message_token(
            fqn, self.process_uuid, self.node_uuid, EntityKind.PUBLISHER, canonical_type(msg_type)
        )
        publisher.entities.append(
            self._declare(
                "publisher",
                fqn,
                lambda: self._session.declare_publisher(
                    fqn, allowed_destination=zenoh.Locality.REMOTE
                ),
            )
        )
        try:
            publisher.entities.append(self._token(fqn, token))
        except LocalProtocolError:
            undeclare(*publisher.entities)
            raise
        with self._lock:
            self._publishers.add(publisher)
        return publisher

    def _close_publisher(self, publisher: Publisher) -> None:
        with self._lock:
            self._publishers.discard(publisher)
        undeclare(*reversed(cast(ZenohPublisher, publisher).entities))

    def _send(self, publisher: Publisher, wire_type: str, payload: Payload) -> None:
        """One put with the spelling as attachment (§4.5)."""
        zenoh_publisher = cast(ZenohPublisher, publisher)
        data = payload if isinstance(payload, bytes) else bytes(payload)
        try:
            zenoh_publisher.entities[0].put(data, attachment=zenoh_publisher.attachments[wire_type])
        except zenoh.ZError as error:
            self.count("send_failures")
            _LOG.debug("Zenoh put on %s failed: %s", publisher.fqn, error)

    def _open_subscription(self, sub: Subscription) -> None:
        """The Zenoh subscriber, then the MS token (a gz publisher may put once it sees it)."""
        entities: list[Any] = []
        cast(ZenohSubscription, sub).entities = entities
        fqn = sub.fqn
        entities.append(
            self._declare(
                "subscriber",
                fqn,
                lambda: self._session.declare_subscriber(
                    fqn,
                    lambda sample: self._on_sample(sub, sample),
                    allowed_origin=zenoh.Locality.REMOTE,
                ),
            )
        )
        token = message_token(
            fqn, self.process_uuid, self.node_uuid, EntityKind.SUBSCRIBER,
            canonical_type(sub.msg_type),
        )  # fmt: skip
        entities.append(self._token(fqn, token))

    def _close_subscription(self, sub: Subscription, *, last: bool) -> None:
        undeclare(*reversed(cast(ZenohSubscription, sub).entities))

    def _on_sample(self, sub: Subscription, sample: zenoh.Sample) -> None:
        """A remote sample on ``sub``'s key: checked as gz does (§4.5), then offered."""
        try:
            taken = take_sample(sub, sample, self.partition, self.settings.max_message_size)
            if taken is not None:
                self.count("messages_received")
                sub.offer(*taken)
        except Exception:  # never out of a Zenoh callback
            self.count("io_errors")
            _LOG.exception("unexpected error handling a sample on %s", sub.fqn)

    # --- the graph --------------------------------------------------------------------------

    def _on_token(self, sample: zenoh.Sample) -> None:
        """One liveliness PUT or DELETE on ``@gz/**`` (§4.4)."""
        try:
            key = str(sample.key_expr)
            self.count("datagrams_received")
            token = parse_token(key)
            if token is None:
                self.count("datagrams_malformed")
                _LOG.debug("malformed liveliness token %r ignored", key)
                return
            ready = self._update_graph(key, token, sample.kind == zenoh.SampleKind.PUT)
            for call in ready:
                self._send_query(call)
            self.graph_changed()
        except Exception:  # never out of a Zenoh callback
            self.count("io_errors")
            _LOG.exception("unexpected error handling a liveliness token")

    def _update_graph(self, key: str, token: GraphToken, alive: bool) -> list[ZenohCall]:
        """Record the token; returns the pending calls it makes ready to send."""
        self._graph.update(key, token, alive)
        if token.kind == EntityKind.SUBSCRIBER and token.process_uuid != self.process_uuid:
            self.subscriber_book.set_subscribers(token.fqn, self._graph.subscribers(token.fqn))
        return self._calls_ready(token) if alive and token.kind == EntityKind.SERVICE else []

    def topic_list(self) -> list[str]:
        """Topics with an MP token in this partition, as known right now."""
        return self._graph.names(EntityKind.PUBLISHER, self.partition)

    def topic_info(self, topic: str) -> list[TopicInfo]:
        """Publishers (MP tokens) of ``topic``; ``address`` is empty in Zenoh mode."""
        return self._graph.infos(EntityKind.PUBLISHER, self.fqn(topic))

    def service_list(self) -> list[str]:
        """Services with an SS token in this partition, as known right now."""
        return self._graph.names(EntityKind.SERVICE, self.partition)

    def service_info(self, service: str) -> list[TopicInfo]:
        """Providers of ``service``; ``msg_type`` is ``"<request type>&<response type>"``."""
        return self._graph.infos(EntityKind.SERVICE, self.fqn(service))

    def observe(self, topic: str) -> list[GraphEndpoint]:
        """Publishers (MP) and subscribers (MS) of ``topic`` in other processes, any partition."""
        return self._graph.observe((decompose(self.fqn(topic)) or ("", topic))[1])

    def graph(self) -> list[GraphEndpoint]:  # GzNode.graph, from the same tokens
        return self._graph.observe()

    def ask_subscribers(self) -> None:
        """Nothing to ask: subscription tokens carry their types."""

    def peer_processes(self) -> int:
        """Other processes holding liveliness tokens."""
        return self._graph.peer_processes()

    def listening(self) -> str:
        """The session's mode and endpoints, and the partition."""
        return f"{self._where}, partition '{self.partition}'"

    # --- shutdown ---------------------------------------------------------------------------

    def _release(self) -> None:
        with self._lock:
            handles: list[Publisher | ServiceOffer] = [*self._publishers, *self._offers.values()]
        for handle in handles:
            handle.closed = True
            undeclare(*reversed(cast(Any, handle).entities))
        undeclare(self._graph_subscriber)
        with contextlib.suppress(zenoh.ZError):
            self._session.close()  # type: ignore[no-untyped-call]

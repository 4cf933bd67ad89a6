"""The Zenoh Gazebo Transport node of gz-transport 15 (Jetty), docs/protocol.md §4.

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
peer is Jetty or later, so our tokens say ``gz.msgs`` (docs/protocol.md §9.3).

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

import collections
import contextlib
import logging
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any, ClassVar, cast

import zenoh

from ros_gz_bridge_py.errors import LocalProtocolError, TransportError
from ros_gz_bridge_py.msgs.names import Spelling, canonical_type, same_message
from ros_gz_bridge_py.transport.api import (
    ONE_WAY_TYPES,
    GraphEndpoint,
    ServiceCall,
    ServiceHandler,
    TopicInfo,
)
from ros_gz_bridge_py.transport.delivery import Payload
from ros_gz_bridge_py.transport.handles import Publisher, ServiceOffer, Subscription, offer_key
from ros_gz_bridge_py.transport.names import decompose
from ros_gz_bridge_py.transport.node import GzNode
from ros_gz_bridge_py.transport.settings import TransportSettings
from ros_gz_bridge_py.transport.zenoh.config import (
    Overrides,
    describe_session,
    limit_message_size,
    session_config,
)
from ros_gz_bridge_py.transport.zenoh.endpoints import (
    ZenohPublisher,
    ZenohServiceOffer,
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
    service_token,
)

_LOG = logging.getLogger("ros_gz_bridge_py.transport")

#: Extra time given to Zenoh's own query timeout, so our deadline decides "timeout" and a
#: query completing before it means "no reply".
QUERY_GRACE = 1.0


@dataclass(eq=False)
class _Call(ServiceCall):
    """A service call waiting for a provider or a reply; finished exactly once."""

    done: bool = field(default=False)

    def matches(self, token: GraphToken) -> bool:
        """True if ``token`` announces a provider of this call's types (either spelling)."""
        return (
            token.kind == EntityKind.SERVICE
            and token.fqn == self.fqn
            and same_message(token.request_type, self.request_type)
            and same_message(token.response_type, self.response_type)
        )


class ZenohGzNode(GzNode):
    """A Gazebo Transport node speaking gz-transport 15's Zenoh protocol."""

    default_peer_spelling: ClassVar[Spelling | None] = Spelling.GZ
    subscription_class = ZenohSubscription
    call_class = _Call

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
        if not self.partition:
            msg = (
                "the Zenoh backend needs a non-empty partition (an empty one gives invalid "
                "liveliness tokens); set GZ_PARTITION or the node's partition"
            )
            raise LocalProtocolError(msg)
        # Graph, offers and calls; the condition also wakes the node thread.
        self._lock = threading.Lock()
        self._calls_changed = threading.Condition(self._lock)
        self._graph = ZenohGraph(self.process_uuid)
        self._publishers: set[Publisher] = set()
        self._offers: dict[tuple[str, str, str], ZenohServiceOffer] = {}
        self._calls: list[_Call] = []
        self._local_calls: collections.deque[_Call] = collections.deque()
        self._stop = False
        chosen = limit_message_size(
            session_config(config, config_overrides), self.settings.max_message_size
        )
        self._where = describe_session(chosen)
        try:
            self._session = zenoh.open(chosen)
        except zenoh.ZError as error:
            msg = f"cannot open the Zenoh session: {error}"
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

    def _declare(self, what: str, fqn: str, declare: Callable[[], Any]) -> Any:
        """Run a Zenoh declaration, turning Zenoh's refusal of a key into our error."""
        self._check_open()
        try:
            return declare()
        except zenoh.ZError as error:
            msg = f"cannot declare the Zenoh {what} for {fqn!r}: {error}"
            raise LocalProtocolError(msg) from error

    def _token(self, fqn: str, token: str) -> zenoh.LivelinessToken:
        liveliness: zenoh.LivelinessToken = self._declare(
            "liveliness token", fqn, lambda: self._session.liveliness().declare_token(token)
        )
        return liveliness

    # --- topics -----------------------------------------------------------------------------

    def _open_publisher(
        self, topic: str, fqn: str, msg_type: str, *, own_socket: bool = False, queue_bytes: int = 0
    ) -> Publisher:
        """A Zenoh publisher on the FQN (remote destinations only) and its MP token;
        ``own_socket`` and ``queue_bytes`` change nothing here (ZeroMQ notions; Zenoh's
        publishers drop what the network cannot take, docs/protocol.md §4.2)."""
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

    # --- services ---------------------------------------------------------------------------

    def _open_offer(
        self, service: str, fqn: str, types: tuple[str, str], handler: ServiceHandler
    ) -> ServiceOffer:
        """A queryable on the service FQN and its SS token (§4.6)."""
        offer = ZenohServiceOffer(self, service, fqn, types, handler)
        token = service_token(
            fqn, self.process_uuid, self.node_uuid, *(canonical_type(t) for t in types)
        )
        try:
            offer.entities.append(
                self._declare(
                    "queryable",
                    fqn,
                    lambda: self._session.declare_queryable(
                        fqn, lambda query: self._on_query(offer, query)
                    ),
                )
            )
            offer.entities.append(self._token(fqn, token))
        except TransportError:
            undeclare(*reversed(offer.entities))
            raise
        with self._lock:
            self._offers[offer.key] = offer
        return offer

    def _close_offer(self, offer: ServiceOffer) -> None:
        with self._lock:
            if self._offers.get(offer.key) is offer:
                del self._offers[offer.key]
        undeclare(*reversed(cast(ZenohServiceOffer, offer).entities))

    def _on_query(self, offer: ServiceOffer, query: zenoh.Query) -> None:
        """Run the handler; reply on success, stay silent on failure (as gz does)."""
        try:
            payload = query.payload
            ok, response = self.call_handler(offer, payload.to_bytes() if payload else b"")
            if ok:
                query.reply(offer.fqn, response)
        except Exception:  # never out of a Zenoh callback
            self.count("io_errors")
            _LOG.exception("unexpected error answering a query on %s", offer.fqn)
        finally:
            with contextlib.suppress(zenoh.ZError):
                query.drop()  # type: ignore[no-untyped-call]

    def _on_node_thread(self) -> bool:
        return threading.current_thread() is self._thread

    def _start_call(self, call: _Call) -> None:
        """``call``'s callback runs exactly once (see the module's threading notes)."""
        with self._lock:
            self._check_open()
            if offer_key(call.fqn, call.request_type, call.response_type) in self._offers:
                self._local_calls.append(call)
                self._calls_changed.notify_all()
                return
            self._calls.append(call)
            self._calls_changed.notify_all()
            ready = any(call.matches(token) for token in self._graph.tokens())
            if ready:
                call.dispatched = True
        if ready:
            self._send_query(call)

    def _send_query(self, call: _Call) -> None:
        """``get`` on the service FQN; payload omitted when empty, as gz does."""
        one_way = call.response_type in ONE_WAY_TYPES

        def on_reply(reply: zenoh.Reply) -> None:
            sample = reply.ok
            if sample is None:
                _LOG.debug("error reply from service %s ignored", call.fqn)
                return
            if not one_way:  # a one-way call is done once sent, whatever comes back
                self._finish(call, True, sample.payload.to_bytes())

        def on_done() -> None:
            if not one_way:
                failed = time.monotonic() < call.deadline
                self._finish(call, False if failed else None, b"")

        remaining = max(0.0, call.deadline - time.monotonic())
        try:
            self._session.get(
                call.fqn,
                zenoh.handlers.Callback(on_reply, on_done),
                payload=call.request or None,
                timeout=remaining + QUERY_GRACE,
            )
        except zenoh.ZError as error:
            self.count("send_failures")
            _LOG.debug("Zenoh get on %s failed: %s", call.fqn, error)
            self._finish(call, False, b"")
            return
        if one_way:
            self._finish(call, True, b"")

    def _finish(self, call: _Call, ok: bool | None, payload: bytes) -> None:
        with self._lock:
            if call.done:
                return
            call.done = True
            with contextlib.suppress(ValueError):
                self._calls.remove(call)
        self.finish_call(call.callback, ok, payload)

    def _run_local_call(self, call: _Call) -> None:
        with self._lock:
            offer = self._offers.get(offer_key(call.fqn, call.request_type, call.response_type))
        if offer is None:
            self._finish(call, False, b"")
            return
        ok, payload = self.call_handler(offer, call.request)
        self._finish(call, ok, b"" if call.response_type in ONE_WAY_TYPES else payload)

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

    def _update_graph(self, key: str, token: GraphToken, alive: bool) -> list[_Call]:
        """Record the token; returns the pending calls it makes ready to send."""
        self._graph.update(key, token, alive)
        if token.kind == EntityKind.SUBSCRIBER and token.process_uuid != self.process_uuid:
            self.subscriber_book.set_subscribers(token.fqn, self._graph.subscribers(token.fqn))
        ready: list[_Call] = []
        if alive and token.kind == EntityKind.SERVICE:
            with self._lock:
                for call in self._calls:
                    if not call.dispatched and call.matches(token):
                        call.dispatched = True
                        ready.append(call)
        return ready

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

    # --- the node thread and shutdown -------------------------------------------------------

    def _node_main(self) -> None:
        """Run local calls and time out calls whose deadline passed."""
        while True:
            with self._calls_changed:
                while True:
                    if self._stop:
                        return
                    now = time.monotonic()
                    expired = [c for c in self._calls if c.deadline <= now]
                    if self._local_calls or expired:
                        break
                    next_deadline = min((c.deadline for c in self._calls), default=None)
                    wait = None if next_deadline is None else next_deadline - now
                    self._calls_changed.wait(wait)
                local = list(self._local_calls)
                self._local_calls.clear()
            for call in local:
                self._run_local_call(call)
            for call in expired:
                self._finish(call, None, b"")

    def _shutdown(self) -> None:
        """End pending calls (as timeouts) and stop the node thread; publishers and offers
        are undeclared by :meth:`_release`, subscriptions by their ``close``."""
        with self._lock:
            self._stop = True
            self._calls_changed.notify_all()
            pending = [*self._calls, *self._local_calls]
        if self._thread is not threading.current_thread():
            self._thread.join()
        for call in pending:
            self._finish(call, None, b"")

    def _release(self) -> None:
        with self._lock:
            handles: list[Publisher | ServiceOffer] = [*self._publishers, *self._offers.values()]
        for handle in handles:
            handle.closed = True
            undeclare(*reversed(cast(Any, handle).entities))
        undeclare(self._graph_subscriber)
        with contextlib.suppress(zenoh.ZError):
            self._session.close()  # type: ignore[no-untyped-call]

"""The Zenoh Gazebo Transport node of gz-transport 15 (Jetty), gz-transport-protocol.md §4.

Each :class:`ZenohNode` opens its own Zenoh session and looks like one gz process (own
process and node UUIDs). Topics and services are Zenoh keys equal to their fully qualified
name; the message type travels as the sample attachment; the graph is the set of ``@gz/…``
liveliness tokens (MP publishers, MS subscriptions, SS services) seen by one liveliness
subscriber on ``@gz/**`` with history.

As in gz: a publisher puts only while some *other* process holds an MS token for its topic
with its type or ``google.protobuf.Message`` (gating); a service call is sent only once an
SS token with exactly its types is known, a provider whose handler fails sends no reply, and
a query that completes without a reply is reported as a failure (a timeout if the deadline
passed first). Local subscriptions get our own messages directly from ``publish``; Zenoh's
own session-local loop-back is switched off (publishers put to remote sessions only,
subscribers take remote samples only), so nothing is delivered twice (gz-transport #961).

Threading model:

* Zenoh runs every callback on a Python thread of its own: one per subscription, one per
  service queryable, one for the liveliness subscriber and one per pending call. Subscription
  callbacks with ``queue_size=None`` and service handlers run there; with ``queue_size=N`` a
  subscription's callback runs on its own delivery thread. Local messages are handed over in
  the publishing thread.
* One node thread (``gz-zenoh``) starts local service calls and ends calls whose deadline
  passed. A ``request_async`` callback runs exactly once, on that thread or on the Zenoh
  thread of the reply; ``request`` must not be called from the node thread.
* Every public method is thread-safe. Bad network input (samples without attachment or with
  another type, undecodable payloads, malformed tokens) never raises out of a Zenoh
  callback: it is counted in ``stats`` and logged at debug level.

Counters: liveliness samples are ``datagrams_received`` (``datagrams_malformed`` when gz
would reject the token); a sample without a readable attachment is ``frames_malformed``, one
of a type the subscription does not take ``unknown_types``.
"""

from __future__ import annotations

import collections
import contextlib
import logging
import threading
import time
import uuid
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import zenoh

from ros_gz_bridge_py.errors import LocalProtocolError, TransportError
from ros_gz_bridge_py.msgs.names import Spelling, canonical_type, same_message
from ros_gz_bridge_py.transport.api import (
    ONE_WAY_TYPES,
    PUBLISHER,
    SUBSCRIBER,
    GraphEndpoint,
    MessageInfo,
    Node,
    ReplyCallback,
    ServiceCall,
    ServiceHandler,
    TopicInfo,
    TransportStats,
)
from ros_gz_bridge_py.transport.delivery import Deliver
from ros_gz_bridge_py.transport.names import decompose, fully_qualified_name
from ros_gz_bridge_py.transport.settings import TransportSettings
from ros_gz_bridge_py.transport.wire_types import RemoteSubscriber, SubscriberBook
from ros_gz_bridge_py.transport.zenoh.config import Overrides, session_config
from ros_gz_bridge_py.transport.zenoh.endpoints import (
    ZenohPublisher,
    ZenohServiceOffer,
    ZenohSubscription,
    undeclare,
)
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
        """True if ``token`` announces a provider for exactly this call."""
        return (
            token.kind == EntityKind.SERVICE
            and token.fqn == self.fqn
            and same_message(token.request_type, self.request_type)
            and same_message(token.response_type, self.response_type)
        )


def _describe_session(config: zenoh.Config) -> str:
    """``Zenoh peer, connect [...], listen [...], multicast scouting on`` for users."""

    def value(key: str) -> str:
        try:
            return str(config.get_json(key))
        except zenoh.ZError:
            return "?"

    mode = value("mode").strip('"')
    mode = "peer" if mode in ("null", "?") else mode
    scouting = "off" if value("scouting/multicast/enabled") == "false" else "on"
    return (
        f"Zenoh {mode}, connect {value('connect/endpoints')}, listen "
        f"{value('listen/endpoints')}, multicast scouting {scouting}"
    )


def _offer_key(fqn: str, request_type: str, response_type: str) -> tuple[str, str, str]:
    """What a call must match to be served by a local offer (either spelling of each type)."""
    return fqn, canonical_type(request_type), canonical_type(response_type)


class ZenohNode(Node):
    """A Gazebo Transport node speaking gz-transport 15's Zenoh protocol."""

    def __init__(
        self,
        partition: str | None = None,
        namespace: str = "",
        settings: TransportSettings | None = None,
        *,
        config: zenoh.Config | None = None,
        config_overrides: Overrides | None = None,
    ) -> None:
        """Open the session (see :mod:`.zenoh_config` for ``config`` and ``config_overrides``).

        Raises:
            LocalProtocolError: the partition or namespace is invalid or the partition empty.
            TransportError: the Zenoh session cannot be opened (e.g. no router in client mode).
        """
        self.settings = settings or TransportSettings.from_env()
        self.partition = self.settings.partition if partition is None else partition
        self.namespace = namespace
        if not self.partition:
            msg = (
                "the Zenoh backend needs a non-empty partition (an empty one gives invalid "
                "liveliness tokens); set GZ_PARTITION or the node's partition"
            )
            raise LocalProtocolError(msg)
        fully_qualified_name(self.partition, namespace, "/check")
        self.process_uuid = str(uuid.uuid4())
        self.node_uuid = str(uuid.uuid4())
        self._counts: collections.Counter[str] = collections.Counter()
        self._count_lock = threading.Lock()
        # Graph, registries and calls; the condition also wakes the node thread and
        # wait_for_publishers.
        self._lock = threading.Lock()
        self._changed = threading.Condition(self._lock)
        self._generation = 0
        self._graph: dict[str, GraphToken] = {}
        #: Remote subscribers (MS tokens) per topic; Zenoh peers are Jetty or later, so they
        #: read gz.msgs names (docs/protocol.md §9).
        self.subscriber_book = SubscriberBook(default_spelling=Spelling.GZ)
        # Read by publishing threads without the lock; replaced, never mutated.
        self._subscriptions: dict[str, tuple[ZenohSubscription, ...]] = {}
        self._publishers: set[ZenohPublisher] = set()
        self._offers: dict[tuple[str, str, str], ZenohServiceOffer] = {}
        self._calls: list[_Call] = []
        self._local_calls: collections.deque[_Call] = collections.deque()
        self._closed = False
        chosen = session_config(config, config_overrides)
        self._where = _describe_session(chosen)
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

    # --- counters ---------------------------------------------------------------------------

    def count(self, name: str, amount: int = 1) -> None:
        """Add to one of the ``stats`` counters (thread-safe)."""
        with self._count_lock:
            self._counts[name] += amount

    @property
    def stats(self) -> TransportStats:
        """A snapshot of the node's counters."""
        with self._count_lock:
            return TransportStats(**self._counts)

    # --- helpers ----------------------------------------------------------------------------

    def _fqn(self, topic: str) -> str:
        return fully_qualified_name(self.partition, self.namespace, topic)

    def _check_open(self) -> None:
        if self._closed:
            msg = "the Gazebo Transport node is closed"
            raise TransportError(msg)

    def _declare(self, what: str, fqn: str, declare: Callable[[], Any]) -> Any:
        """Run a Zenoh declaration, turning Zenoh's refusal of a key into our error."""
        self._check_open()
        try:
            return declare()
        except zenoh.ZError as error:
            msg = f"cannot declare the Zenoh {what} for {fqn!r}: {error}"
            raise LocalProtocolError(msg) from error

    def _declare_token(self, fqn: str, token: str) -> zenoh.LivelinessToken:
        liveliness: zenoh.LivelinessToken = self._declare(
            "liveliness token", fqn, lambda: self._session.liveliness().declare_token(token)
        )
        return liveliness

    # --- topics -----------------------------------------------------------------------------

    def advertise(self, topic: str, msg_type: str) -> ZenohPublisher:
        """Declare a Zenoh publisher on the topic's FQN and its MP token (gz.msgs spelling:
        Zenoh peers are Jetty or later)."""
        fqn = self._fqn(topic)
        token = message_token(
            fqn, self.process_uuid, self.node_uuid, EntityKind.PUBLISHER, canonical_type(msg_type)
        )
        zenoh_publisher = self._declare(
            "publisher",
            fqn,
            lambda: self._session.declare_publisher(fqn, allowed_destination=zenoh.Locality.REMOTE),
        )
        try:
            liveliness = self._declare_token(fqn, token)
        except LocalProtocolError:
            undeclare(zenoh_publisher)
            raise
        publisher = ZenohPublisher(self, topic, fqn, msg_type, (zenoh_publisher, liveliness))
        with self._lock:
            self._publishers.add(publisher)
        return publisher

    def forget_publisher(self, publisher: ZenohPublisher) -> None:
        """Drop ``publisher`` from the registry (called by its ``close``)."""
        with self._lock:
            self._publishers.discard(publisher)

    def publish(
        self,
        publisher: ZenohPublisher,
        payload: bytes | bytearray | memoryview,
        as_type: str | None = None,
    ) -> None:
        """Local delivery, then one put per spelling a remote MS token needs (§4.5 gating);
        ``as_type`` limits both to that spelling."""
        fqn, msg_type = publisher.fqn, publisher.msg_type
        data = payload if isinstance(payload, bytes) else bytes(payload)
        if as_type is None or as_type == msg_type:
            local = [
                sub
                for sub in self._subscriptions.get(fqn, ())
                if not sub.ignore_local and sub.accepts(msg_type)
            ]
            if local:
                info = MessageInfo(
                    publisher.topic, msg_type, self.partition, "", intra_process=True
                )
                for sub in local:
                    sub.offer(data, info)
        for wire_type in publisher.wire_types():
            if as_type is not None and wire_type != as_type:
                continue
            try:
                publisher.zenoh_publisher.put(data, attachment=publisher.attachments[wire_type])
            except zenoh.ZError as error:
                self.count("send_failures")
                _LOG.debug("Zenoh put on %s failed: %s", fqn, error)

    def has_connections(self, publisher: ZenohPublisher) -> bool:
        """True if a remote MS token or a local subscription matches ``publisher``."""
        if publisher.wire_types():
            return True
        return any(
            not sub.ignore_local and sub.accepts(publisher.msg_type)
            for sub in self._subscriptions.get(publisher.fqn, ())
        )

    def _add_subscription(
        self,
        topic: str,
        msg_type: str,
        deliver: Deliver,
        *,
        ignore_local: bool,
        queue_size: int | None,
        on_delivery_start: Callable[[], None] | None,
    ) -> ZenohSubscription:
        fqn = self._fqn(topic)
        token = message_token(
            fqn, self.process_uuid, self.node_uuid, EntityKind.SUBSCRIBER, canonical_type(msg_type)
        )
        sub = ZenohSubscription(
            self, topic, fqn, msg_type, deliver,
            ignore_local=ignore_local, queue_size=queue_size, on_delivery_start=on_delivery_start,
        )  # fmt: skip
        try:
            # The subscriber first: once a gz publisher sees the token, it may put.
            zenoh_subscriber = self._declare(
                "subscriber",
                fqn,
                lambda: self._session.declare_subscriber(
                    fqn,
                    lambda sample: self._on_sample(sub, sample),
                    allowed_origin=zenoh.Locality.REMOTE,
                ),
            )
            sub.entities.append(zenoh_subscriber)
            sub.entities.append(self._declare_token(fqn, token))
        except TransportError:
            sub.close()
            raise
        with self._lock:
            self._subscriptions[fqn] = (*self._subscriptions.get(fqn, ()), sub)
        return sub

    def forget_subscription(self, sub: ZenohSubscription) -> None:
        """Stop local delivery to ``sub`` (called by its ``close``)."""
        with self._lock:
            remaining = tuple(s for s in self._subscriptions.get(sub.fqn, ()) if s is not sub)
            if remaining:
                self._subscriptions[sub.fqn] = remaining
            else:
                self._subscriptions.pop(sub.fqn, None)

    def _on_sample(self, sub: ZenohSubscription, sample: zenoh.Sample) -> None:
        """A remote sample on ``sub``'s key: check the attachment as gz does (§4.5)."""
        try:
            attachment = sample.attachment
            if attachment is None:
                self.count("frames_malformed")
                _LOG.debug("sample without attachment on %s dropped", sub.fqn)
                return
            msg_type = attachment.to_bytes().decode()
            if not sub.accepts(msg_type):
                self.count("unknown_types")
                _LOG.debug("sample of type %r on %s dropped", msg_type, sub.fqn)
                return
            self.count("messages_received")
            name = (decompose(sub.fqn) or ("", sub.topic))[1]
            info = MessageInfo(name, msg_type, self.partition, "", intra_process=False)
            sub.offer(sample.payload.to_bytes(), info)
        except UnicodeDecodeError:
            self.count("frames_malformed")
            _LOG.debug("sample with a non-UTF-8 attachment on %s dropped", sub.fqn)
        except Exception:  # never out of a Zenoh callback
            self.count("io_errors")
            _LOG.exception("unexpected error handling a sample on %s", sub.fqn)

    # --- services ---------------------------------------------------------------------------

    def advertise_service(
        self, service: str, request_type: str, response_type: str, handler: ServiceHandler
    ) -> ZenohServiceOffer:
        """Declare a queryable on the service FQN and its SS token (§4.6)."""
        fqn = self._fqn(service)
        token = service_token(
            fqn,
            self.process_uuid,
            self.node_uuid,
            canonical_type(request_type),
            canonical_type(response_type),
        )
        offer = ZenohServiceOffer(self, service, (fqn, request_type, response_type), handler)
        try:
            queryable = self._declare(
                "queryable",
                fqn,
                lambda: self._session.declare_queryable(
                    fqn, lambda query: self._on_query(offer, query)
                ),
            )
            offer.entities.append(queryable)
            offer.entities.append(self._declare_token(fqn, token))
        except TransportError:
            offer.close()
            raise
        with self._lock:
            self._offers[_offer_key(*offer.key)] = offer
        return offer

    def forget_offer(self, offer: ZenohServiceOffer) -> None:
        """Drop ``offer`` from the local-call registry (called by its ``close``)."""
        with self._lock:
            if self._offers.get(_offer_key(*offer.key)) is offer:
                del self._offers[_offer_key(*offer.key)]

    def _run_handler(self, offer: ZenohServiceOffer, request: bytes) -> tuple[bool, bytes]:
        try:
            ok, payload = offer.handler(request)
        except Exception:
            self.count("callback_errors")
            _LOG.exception("service handler for %s raised", offer.service)
            return False, b""
        return ok, payload if ok else b""

    def _on_query(self, offer: ZenohServiceOffer, query: zenoh.Query) -> None:
        """Run the handler; reply on success, stay silent on failure (as gz does)."""
        try:
            payload = query.payload
            ok, response = self._run_handler(offer, payload.to_bytes() if payload else b"")
            if ok:
                query.reply(offer.key[0], response)
        except Exception:  # never out of a Zenoh callback
            self.count("io_errors")
            _LOG.exception("unexpected error answering a query on %s", offer.key[0])
        finally:
            with contextlib.suppress(zenoh.ZError):
                query.drop()  # type: ignore[no-untyped-call]

    def _on_node_thread(self) -> bool:
        return threading.current_thread() is self._thread

    def request_async(  # noqa: PLR0917 - positional order fixed by the API contract
        self,
        service: str,
        request: bytes,
        request_type: str,
        response_type: str,
        timeout: float,
        callback: ReplyCallback,
    ) -> None:
        """Call ``service``; ``callback`` runs exactly once (see the module's threading notes)."""
        call = _Call(
            self._fqn(service), bytes(request), request_type, response_type,
            time.monotonic() + timeout, callback,
        )  # fmt: skip
        with self._lock:
            self._check_open()
            if _offer_key(call.fqn, request_type, response_type) in self._offers:
                self._local_calls.append(call)
                self._changed.notify_all()
                return
            self._calls.append(call)
            self._changed.notify_all()
            ready = any(call.matches(token) for token in self._graph.values())
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
        try:
            call.callback(ok, payload)
        except Exception:
            self.count("callback_errors")
            _LOG.exception("service reply callback for %s raised", call.fqn)

    def _run_local_call(self, call: _Call) -> None:
        with self._lock:
            offer = self._offers.get(_offer_key(call.fqn, call.request_type, call.response_type))
        if offer is None:
            self._finish(call, False, b"")
            return
        ok, payload = self._run_handler(offer, call.request)
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
        except Exception:  # never out of a Zenoh callback
            self.count("io_errors")
            _LOG.exception("unexpected error handling a liveliness token")

    def _update_graph(self, key: str, token: GraphToken, alive: bool) -> list[_Call]:
        """Record the token; returns the pending calls it makes ready to send."""
        ready: list[_Call] = []
        with self._lock:
            if alive:
                self._graph[key] = token
            else:
                self._graph.pop(key, None)
            if token.kind == EntityKind.SUBSCRIBER and token.process_uuid != self.process_uuid:
                self._update_subscribers(token.fqn)
            if alive and token.kind == EntityKind.SERVICE:
                for call in self._calls:
                    if not call.dispatched and call.matches(token):
                        call.dispatched = True
                        ready.append(call)
            self._generation += 1
            self._changed.notify_all()
        return ready

    def _update_subscribers(self, fqn: str) -> None:
        """The MS tokens of other processes on ``fqn``, per node (caller holds the lock)."""
        types: dict[tuple[str, str], set[str]] = {}
        for token in self._graph.values():
            if (
                token.kind == EntityKind.SUBSCRIBER
                and token.fqn == fqn
                and token.process_uuid != self.process_uuid
            ):
                types.setdefault((token.process_uuid, token.node_uuid), set()).add(token.msg_type)
        self.subscriber_book.set_subscribers(
            fqn, tuple(RemoteSubscriber(p, n, frozenset(t)) for (p, n), t in types.items())
        )

    def _names(self, kind: EntityKind) -> list[str]:
        with self._lock:
            tokens = list(self._graph.values())
        own = "/" + self.partition if not self.partition.startswith("/") else self.partition
        return sorted({t.topic for t in tokens if t.kind == kind and t.partition == own})

    def _infos(self, kind: EntityKind, topic: str) -> list[TopicInfo]:
        fqn = self._fqn(topic)
        with self._lock:
            tokens = [t for t in self._graph.values() if t.kind == kind and t.fqn == fqn]
        return [
            TopicInfo(
                t.topic,
                t.msg_type,
                "",
                t.process_uuid,
                t.node_uuid,
                request_type=t.request_type,
                response_type=t.response_type,
            )
            for t in tokens
        ]

    def topic_list(self) -> list[str]:
        """Topics with an MP token in this partition, as known right now."""
        return self._names(EntityKind.PUBLISHER)

    def topic_info(self, topic: str) -> list[TopicInfo]:
        """Publishers (MP tokens) of ``topic``; ``address`` is empty in Zenoh mode."""
        return self._infos(EntityKind.PUBLISHER, topic)

    def service_list(self) -> list[str]:
        """Services with an SS token in this partition, as known right now."""
        return self._names(EntityKind.SERVICE)

    def service_info(self, service: str) -> list[TopicInfo]:
        """Providers of ``service``; ``msg_type`` is ``"<request type>&<response type>"``."""
        return self._infos(EntityKind.SERVICE, service)

    def observe(self, topic: str) -> list[GraphEndpoint]:
        """Publishers (MP) and subscribers (MS) of ``topic`` in other processes, from their
        liveliness tokens, in every partition."""
        name = (decompose(self._fqn(topic)) or ("", topic))[1]
        roles: dict[str, str] = {EntityKind.PUBLISHER: PUBLISHER, EntityKind.SUBSCRIBER: SUBSCRIBER}
        with self._lock:
            tokens = list(self._graph.values())
        return [
            GraphEndpoint(roles[t.kind], t.partition.removeprefix("/"), name, t.msg_type,
                          t.process_uuid, "")
            for t in tokens
            if t.kind in roles and t.topic == name and t.process_uuid != self.process_uuid
        ]  # fmt: skip

    def ask_subscribers(self) -> None:
        """Nothing to ask: subscription tokens carry their types."""

    def peer_processes(self) -> int:
        """Other processes holding liveliness tokens."""
        with self._lock:
            return len({t.process_uuid for t in self._graph.values()} - {self.process_uuid})

    def listening(self) -> str:
        """The session's mode and endpoints, and the partition."""
        return f"{self._where}, partition '{self.partition}'"

    def wait_for_publishers(
        self, topic: str, timeout: float, msg_type: str | None = None
    ) -> list[TopicInfo]:
        """Publishers of ``topic`` (of ``msg_type`` if given) as soon as one is known."""
        deadline = time.monotonic() + timeout
        while True:
            seen = self._generation
            infos = self.topic_info(topic)
            found = [i for i in infos if msg_type is None or i.msg_type == msg_type]
            remaining = deadline - time.monotonic()
            if found or remaining <= 0:
                return found
            self._wait_for_change(seen, remaining)

    def _wait_for_change(self, seen: int, timeout: float) -> None:
        with self._changed:
            self._changed.wait_for(lambda: self._generation != seen, timeout)

    # --- the node thread and shutdown -------------------------------------------------------

    def _node_main(self) -> None:
        """Run local calls and time out calls whose deadline passed."""
        while True:
            with self._changed:
                while True:
                    if self._closed:
                        return
                    now = time.monotonic()
                    expired = [c for c in self._calls if c.deadline <= now]
                    if self._local_calls or expired:
                        break
                    next_deadline = min((c.deadline for c in self._calls), default=None)
                    wait = None if next_deadline is None else next_deadline - now
                    self._changed.wait(wait)
                local = list(self._local_calls)
                self._local_calls.clear()
            for call in local:
                self._run_local_call(call)
            for call in expired:
                self._finish(call, None, b"")

    def close(self) -> None:
        """Undeclare every token and entity, end pending calls (as timeouts), close the session."""
        with self._lock:
            if self._closed:
                return
            self._closed = True
            self._changed.notify_all()
            pending = [*self._calls, *self._local_calls]
            handles: list[ZenohPublisher | ZenohSubscription | ZenohServiceOffer] = [
                *self._publishers,
                *(sub for subs in self._subscriptions.values() for sub in subs),
                *self._offers.values(),
            ]
        if self._thread is not threading.current_thread():
            self._thread.join()
        for handle in handles:
            handle.close()
        undeclare(self._graph_subscriber)
        for call in pending:
            self._finish(call, None, b"")
        with contextlib.suppress(zenoh.ZError):
            self._session.close()  # type: ignore[no-untyped-call]

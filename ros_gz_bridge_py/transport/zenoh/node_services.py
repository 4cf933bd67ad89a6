"""Services over Zenoh (docs/protocol-zenoh.md §4.6): the service half of
:class:`~.node.ZenohGzNode`.

:class:`ZenohServices` offers services (a queryable and its SS token each) and calls them: a
call waits for a provider's token, is sent as a ``get`` and finished exactly once, by its reply,
by the query ending without one, or by its deadline. Calls to an offer of this node run on the
node thread (``gz-zenoh``), which also ends the calls whose deadline passed. The node opens the
session, keeps the graph of tokens and starts the thread.
"""

from __future__ import annotations

import collections
import contextlib
import logging
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any, cast

import zenoh

from ros_gz_bridge_py.errors import LocalProtocolError, TransportError
from ros_gz_bridge_py.msgs.names import canonical_type, same_message
from ros_gz_bridge_py.transport.api import ONE_WAY_TYPES, ServiceCall, ServiceHandler
from ros_gz_bridge_py.transport.handles import ServiceOffer, offer_key
from ros_gz_bridge_py.transport.node import GzNode
from ros_gz_bridge_py.transport.zenoh.endpoints import ZenohServiceOffer, undeclare
from ros_gz_bridge_py.transport.zenoh.graph import ZenohGraph
from ros_gz_bridge_py.transport.zenoh.keys import EntityKind, GraphToken, service_token

_LOG = logging.getLogger("ros_gz_bridge_py.transport")

#: Extra time given to Zenoh's own query timeout, so our deadline decides "timeout" and a
#: query completing before it means "no reply".
QUERY_GRACE = 1.0


@dataclass(eq=False)
class ZenohCall(ServiceCall):
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


class ZenohServices(GzNode):
    """Offers and calls of a Zenoh node (its session, graph and thread are the node's)."""

    call_class = ZenohCall
    _session: zenoh.Session
    _graph: ZenohGraph
    _thread: threading.Thread

    def _start_services(self) -> None:
        """The service half's state (the node calls it first thing after ``GzNode``'s set-up)."""
        # Graph, offers and calls; the condition also wakes the node thread.
        self._lock = threading.Lock()
        self._calls_changed = threading.Condition(self._lock)
        self._offers: dict[tuple[str, str, str], ZenohServiceOffer] = {}
        self._calls: list[ZenohCall] = []
        self._local_calls: collections.deque[ZenohCall] = collections.deque()
        self._stop = False

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

    def _start_call(self, call: ZenohCall) -> None:
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

    def _send_query(self, call: ZenohCall) -> None:
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

    def _finish(self, call: ZenohCall, ok: bool | None, payload: bytes) -> None:
        with self._lock:
            if call.done:
                return
            call.done = True
            with contextlib.suppress(ValueError):
                self._calls.remove(call)
        self.finish_call(call.callback, ok, payload)

    def _run_local_call(self, call: ZenohCall) -> None:
        with self._lock:
            offer = self._offers.get(offer_key(call.fqn, call.request_type, call.response_type))
        if offer is None:
            self._finish(call, False, b"")
            return
        ok, payload = self.call_handler(offer, call.request)
        self._finish(call, ok, b"" if call.response_type in ONE_WAY_TYPES else payload)

    def _calls_ready(self, token: GraphToken) -> list[ZenohCall]:
        """The pending calls that ``token``, a new provider, lets us send (once each)."""
        ready: list[ZenohCall] = []
        with self._lock:
            for call in self._calls:
                if not call.dispatched and call.matches(token):
                    call.dispatched = True
                    ready.append(call)
        return ready

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

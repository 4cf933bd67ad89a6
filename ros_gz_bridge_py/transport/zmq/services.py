"""The service side of a :class:`~ros_gz_bridge_py.transport.zmq.node.ZmqGzNode`.

The protocol: docs/protocol-zmq-data.md §2.9.

:class:`ServiceRouter` keeps the node's service offers, its calls waiting for a provider, a
route or a response, and the ROUTER sends retried until their peer is routable. It runs on the
node's I/O thread only (the node posts every call into it), so it takes no lock; the node owns
the sockets and the discovery engine and hands them in.
"""

from __future__ import annotations

import contextlib
import errno
import logging
import time
import uuid
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import zmq

from ros_gz_bridge_py.msgs.names import same_message
from ros_gz_bridge_py.transport.api import ONE_WAY_TYPES, ReplyCallback, ServiceCall
from ros_gz_bridge_py.transport.handles import ServiceOffer, offer_key
from ros_gz_bridge_py.transport.zmq.discovery import DiscoveryEngine
from ros_gz_bridge_py.transport.zmq.discovery_events import Outgoing
from ros_gz_bridge_py.transport.zmq.endpoints import ZmqServiceOffer
from ros_gz_bridge_py.transport.zmq.wire import (
    Frame,
    ServiceRequest,
    ServiceResponse,
    decode_request,
    decode_response,
    encode_request,
    encode_response,
    is_tcp_endpoint,
)

_LOG = logging.getLogger("ros_gz_bridge_py.transport")

#: How long a response to a peer that is not routable yet is retried (§2.9.3: gz sleeps
#: 100 ms after connecting; we retry instead of sleeping). A request is retried until its
#: call's deadline: given up after this, a provider busy for a moment (a simulator loading)
#: never got it, and the call failed at its timeout with the provider back long before.
ROUTE_RETRY = 1.0


@dataclass(eq=False)
class PendingCall(ServiceCall):
    """A service call waiting for a provider, a route or a response."""

    request_uuid: str = field(default_factory=lambda: str(uuid.uuid4()))


@dataclass(eq=False)
class RoutedSend:
    """A ROUTER send retried while the peer is not routable yet."""

    sock: Any
    frames: list[Frame]
    deadline: float
    on_sent: Callable[[], None] | None = None


@dataclass(frozen=True)
class RouterSockets:
    """What the router needs of its node: the service discovery engine and how to send on its
    socket, the two ROUTER sockets it sends on, and the addresses replies come back to."""

    engine: DiscoveryEngine
    announce: Callable[[list[Outgoing]], None]
    requester: Any
    replier: Any
    response_address: str
    response_id: str
    node_uuid: str


class ServiceRouter:
    """Offers, outgoing calls and retried ROUTER sends of one node (I/O thread only).

    ``run_handler`` runs an offer's handler (counting its errors); ``finish`` runs a call's
    callback (likewise): the node's shared ways of doing both.
    """

    def __init__(
        self,
        sockets: RouterSockets,
        count: Callable[[str], None],
        run_handler: Callable[[ServiceOffer, bytes], tuple[bool, bytes]],
        finish: Callable[[ReplyCallback, bool | None, bytes], None],
    ) -> None:
        self._io = sockets
        self._count = count
        self._run_handler = run_handler
        self._finish_callback = finish
        self._offers: dict[tuple[str, str, str], ZmqServiceOffer] = {}
        self._calls: dict[str, PendingCall] = {}
        self._routed: list[RoutedSend] = []
        self._requester_connected: set[str] = set()
        self._replier_connected: set[str] = set()

    # --- offers -----------------------------------------------------------------------------

    def add_offer(self, offer: ZmqServiceOffer) -> None:
        self._offers[offer.key] = offer
        self._io.announce(self._io.engine.advertise(offer.record))

    def remove_offer(self, offer: ZmqServiceOffer) -> None:
        if self._offers.get(offer.key) is offer:
            del self._offers[offer.key]
        self._io.announce(self._io.engine.unadvertise(offer.record))

    def on_request(self, frames: list[Frame]) -> None:
        """§2.9.3: look up the handler, run it, answer unless one-way."""
        request = decode_request(frames)
        key = offer_key(request.service, request.request_type, request.response_type)
        offer = self._offers.get(key)
        if offer is None:
            self._count("requests_unhandled")
            _LOG.debug("no handler for service request %s", key)
            return
        one_way = request.response_type in ONE_WAY_TYPES
        if not one_way and not is_tcp_endpoint(request.response_address):
            self._count("addresses_refused")  # docs/protocol-zmq-discovery.md §2.3.1: tcp:// only
            _LOG.debug("service request with response address %r", request.response_address)
            return
        ok, payload = self._run_handler(offer, bytes(request.payload))
        if one_way:
            return
        replier = self._io.replier
        _connect_once(replier, request.response_address, self._replier_connected)
        response = ServiceResponse(
            request.service, request.node_uuid, request.request_uuid, payload, ok
        )
        frames_out = encode_response(request.response_id, response)
        self._routed.append(RoutedSend(replier, frames_out, time.monotonic() + ROUTE_RETRY))

    # --- calls ------------------------------------------------------------------------------

    def start_call(self, call: PendingCall) -> None:
        """A local offer answers at once; otherwise send to a known provider or ask for one."""
        offer = self._offers.get(offer_key(call.fqn, call.request_type, call.response_type))
        if offer is not None:
            ok, payload = self._run_handler(offer, call.request)
            self._finish(call, ok, b"" if call.response_type in ONE_WAY_TYPES else payload)
            return
        self._calls[call.request_uuid] = call
        if not self._dispatch(call):
            self._io.announce(self._io.engine.subscribe(call.fqn))

    def provider_gone(self, address: str) -> None:
        """A provider record went away: disconnect the requester from its address when no
        provider is left there (the requester only sends, so no message is half read)."""
        if address not in self._requester_connected:
            return
        if any(r.address == address for r in self._io.engine.all_publishers()):
            return
        self._requester_connected.discard(address)
        with contextlib.suppress(zmq.ZMQError):
            self._io.requester.disconnect(address)

    def provider_found(self, fqn: str) -> None:
        """A provider of ``fqn`` was discovered: send the calls that waited for one."""
        for call in [c for c in self._calls.values() if not c.dispatched and c.fqn == fqn]:
            self._dispatch(call)

    def _dispatch(self, call: PendingCall) -> bool:
        """Send ``call`` to the first provider of its types (either spelling: the request
        carries the provider's); False if none is known."""
        for record in self._io.engine.remote_publishers(call.fqn):
            srv = record.srv
            if (
                srv is None
                or not same_message(srv.request_type, call.request_type)
                or not same_message(srv.response_type, call.response_type)
            ):
                continue
            requester = self._io.requester
            _connect_once(requester, record.address, self._requester_connected)
            request = ServiceRequest(
                call.fqn, self._io.response_address, self._io.response_id, self._io.node_uuid,
                call.request_uuid, call.request, srv.request_type, srv.response_type,
            )  # fmt: skip
            one_way = call.response_type in ONE_WAY_TYPES
            call.dispatched = True
            self._routed.append(
                RoutedSend(
                    requester,
                    encode_request(srv.socket_id, request),
                    call.deadline,  # a provider busy for a moment takes it later
                    (lambda: self._finish(call, True, b"")) if one_way else None,
                )
            )
            return True
        return False

    def on_response(self, frames: list[Frame]) -> None:
        response = decode_response(frames)
        call = self._calls.get(response.request_uuid)
        if call is None or call.fqn != response.service or response.node_uuid != self._io.node_uuid:
            self._count("responses_unmatched")
            _LOG.debug("unmatched service response for %s", response.service)
            return
        self._finish(call, response.ok, bytes(response.payload))

    def _finish(self, call: PendingCall, ok: bool | None, payload: bytes) -> None:
        self._calls.pop(call.request_uuid, None)
        self._finish_callback(call.callback, ok, payload)

    def cancel_all(self) -> None:
        """Every waiting call fails (the node is closing)."""
        for call in list(self._calls.values()):
            self._finish(call, None, b"")

    # --- the I/O thread's turn --------------------------------------------------------------

    @property
    def retrying(self) -> bool:
        """True while a ROUTER send waits for its peer (the node then polls briefly)."""
        return bool(self._routed)

    def next_deadline(self, default: float) -> float:
        """The earliest call deadline, or ``default`` if it comes first."""
        return min([default, *(call.deadline for call in self._calls.values())])

    def turn(self, now: float) -> None:
        """Retry the waiting ROUTER sends and fail the calls whose time is up."""
        pending, self._routed = self._routed, []
        for routed in pending:
            try:
                routed.sock.send_multipart(routed.frames, zmq.NOBLOCK)
            except zmq.ZMQError as error:
                if error.errno in (errno.EHOSTUNREACH, zmq.EAGAIN) and now < routed.deadline:
                    self._routed.append(routed)
                else:
                    self._count("send_failures")
                    _LOG.debug("service message not routable: %s", error)
                continue
            if routed.on_sent is not None:
                routed.on_sent()
        for call in [c for c in self._calls.values() if c.deadline <= now]:
            self._finish(call, None, b"")


def _connect_once(sock: Any, address: str, connected: set[str]) -> None:
    """Connect ``sock`` to ``address`` the first time only (``connected`` remembers)."""
    if address not in connected:
        sock.connect(address)
        connected.add(address)

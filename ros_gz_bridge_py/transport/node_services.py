"""Gazebo Transport services, as every backend shares them: offering, calling and waiting.

:class:`ServiceEnds` is the service half of :class:`~ros_gz_bridge_py.transport.node.GzNode`:
offers and calls go through the backend's hooks (open and close an offer, start a call, tell
whether the caller is on the node's own thread); what is the same everywhere is here: blocking
calls over asynchronous ones, handlers and reply callbacks that may raise (counted, never
raised to the backend), the call record of the backend's class.
"""

from __future__ import annotations

import abc
import logging
import threading
import time
from typing import Any, ClassVar

from ros_gz_bridge_py.errors import TransportError, TransportTimeoutError
from ros_gz_bridge_py.transport.api import ReplyCallback, ServiceCall, ServiceHandler
from ros_gz_bridge_py.transport.handles import ServiceOffer

_LOG = logging.getLogger("ros_gz_bridge_py.transport")


class ServiceEnds(abc.ABC):
    """Provide and call services (mixed into ``GzNode``, which gives the names, the counters
    and the open check)."""

    #: The backend's record of a service call (its own state added to :class:`ServiceCall`).
    call_class: ClassVar[type[ServiceCall]] = ServiceCall
    closed: bool

    @abc.abstractmethod
    def fqn(self, topic: str) -> str:
        """The fully qualified name of ``topic`` (or a service) in this node."""

    @abc.abstractmethod
    def count(self, name: str, amount: int = 1) -> None:
        """Add to the node's counter ``name``."""

    @abc.abstractmethod
    def _check_open(self) -> None:
        """Raises TransportError when the node is closed."""

    def advertise_service(
        self, service: str, request_type: str, response_type: str, handler: ServiceHandler
    ) -> ServiceOffer:
        """Provide ``service``: calls of either spelling of the two types reach ``handler``,
        which runs on a backend thread; an exception means failure.

        Raises:
            LocalProtocolError: the name is not a valid Gazebo service name.
            TransportError: the node is closed.
        """
        self._check_open()
        return self._open_offer(service, self.fqn(service), (request_type, response_type), handler)

    def unadvertise_service(self, offer: ServiceOffer) -> None:
        """Withdraw ``offer`` (called by its ``close``)."""
        if not self.closed:
            self._close_offer(offer)

    def request(
        self, service: str, request: bytes, request_type: str, response_type: str, timeout: float
    ) -> tuple[bool, bytes]:
        """Call a service and wait for the reply (one-way calls return (True, b"") once sent).

        Raises:
            TransportTimeoutError: no reply within ``timeout`` seconds.
            TransportError: called from the node's own thread, which would wait for itself.
        """
        if self._on_node_thread():
            msg = "request() would block the node's own thread; use request_async() in callbacks"
            raise TransportError(msg)
        done = threading.Event()
        result: list[tuple[bool | None, bytes]] = []

        def on_reply(ok: bool | None, payload: bytes) -> None:
            result.append((ok, payload))
            done.set()

        self.request_async(service, request, request_type, response_type, timeout, on_reply)
        done.wait()
        ok, payload = result[0]
        if ok is None:
            msg = f"service {service!r} did not answer within {timeout} s"
            raise TransportTimeoutError(msg)
        return ok, payload

    def call_handler(self, offer: ServiceOffer, request: bytes) -> tuple[bool, bytes]:
        """Run ``offer``'s handler: (False, b"") when it raises (counted) or fails."""
        try:
            ok, payload = offer.handler(request)
        except Exception:
            self.count("callback_errors")
            _LOG.exception("service handler for %s raised", offer.service)
            return False, b""
        return ok, payload if ok else b""

    def finish_call(self, callback: ReplyCallback, ok: bool | None, payload: bytes) -> None:
        """Run a ``request_async`` callback, counting (never raising) its errors."""
        try:
            callback(ok, payload)
        except Exception:
            self.count("callback_errors")
            _LOG.exception("service reply callback raised")

    def request_async(  # noqa: PLR0917 - positional order fixed by the API contract
        self,
        service: str,
        request: bytes,
        request_type: str,
        response_type: str,
        timeout: float,
        callback: ReplyCallback,
    ) -> None:
        """Call a provider of either spelling of the two types; ``callback(ok, reply)`` runs
        exactly once: (True/False, reply) on a reply, (None, b"") on timeout, (True, b"")
        once sent for a one-way call (response ``gz.msgs.Empty``)."""
        self._check_open()
        deadline = time.monotonic() + timeout
        call = self.call_class(
            self.fqn(service), bytes(request), request_type, response_type, deadline, callback
        )
        self._start_call(call)

    # --- the backend's hooks ------------------------------------------------------------------

    @abc.abstractmethod
    def _open_offer(
        self, service: str, fqn: str, types: tuple[str, str], handler: ServiceHandler
    ) -> ServiceOffer:
        """Create and announce a service offer."""

    @abc.abstractmethod
    def _close_offer(self, offer: ServiceOffer) -> None:
        """Withdraw ``offer``."""

    @abc.abstractmethod
    def _start_call(self, call: Any) -> None:  # Any: each backend takes its call_class
        """Start ``call`` (a :attr:`call_class`); its callback runs once, through
        :meth:`finish_call`."""

    @abc.abstractmethod
    def _on_node_thread(self) -> bool:
        """True when the caller runs on the node's own thread (where blocking is forbidden)."""

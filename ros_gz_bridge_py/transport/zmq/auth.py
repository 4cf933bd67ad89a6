"""ZeroMQ PLAIN authentication of the data plane, as gz-transport does it (docs/protocol-zmq-data.md
§2.8.6).

With ``GZ_TRANSPORT_USERNAME`` and ``GZ_TRANSPORT_PASSWORD`` set, the PUB socket is a PLAIN
server in ZAP domain :data:`ZAP_DOMAIN` and every SUB socket a PLAIN client with the same
credentials (``sockets.py``). libzmq asks the ZAP handler of the socket's context, a REP
socket bound to ``inproc://zeromq.zap.01``, about each connection (ZAP, ZeroMQ RFC 27); this
one answers 200 for PLAIN with exactly our credentials and 400 otherwise. Requests of another
domain (sockets that are not ours to judge) are let through, as without a handler.
"""

from __future__ import annotations

import hmac
import logging
from typing import Any

import zmq

from ros_gz_bridge_py.transport.throttle import Throttle

_LOG = logging.getLogger("ros_gz_bridge_py.transport")

#: The ZAP domain of our PUB socket (gz-transport: ``gz-auth``, Fortress ``ign-auth``; the
#: domain never leaves the process, so the spelling does not matter on the wire).
ZAP_DOMAIN = "gz-auth"
#: Where libzmq sends its ZAP requests (ZeroMQ RFC 27).
ZAP_ENDPOINT = "inproc://zeromq.zap.01"
#: The frames of a ZAP request up to the mechanism (version, id, domain, address, identity,
#: mechanism), and with PLAIN's user and password.
_MECHANISM_FRAMES = 6
_PLAIN_FRAMES = 8
#: Seconds between two warnings about refused subscribers.
WARN_PERIOD = 10.0


class ZapHandler:
    """Answers libzmq's ZAP requests on the I/O thread (poll :attr:`socket`, then call
    :meth:`handle`)."""

    def __init__(self, context: Any, credentials: tuple[str, str], count: Any = None) -> None:
        self._user = credentials[0].encode()
        self._password = credentials[1].encode()
        self._count = count
        self._warning = Throttle(WARN_PERIOD)
        self.refused = 0
        self.socket: Any = context.socket(zmq.REP)
        self.socket.setsockopt(zmq.LINGER, 0)
        self.socket.bind(ZAP_ENDPOINT)

    def handle(self) -> None:
        """Answer every waiting request."""
        while True:
            try:
                request = self.socket.recv_multipart(zmq.NOBLOCK)
            except zmq.Again:
                return
            self.socket.send_multipart(self.answer(request))

    def answer(self, request: list[bytes]) -> list[bytes]:
        """The reply frames to one request: version, request id, status, text, user, metadata."""
        version, request_id = [*request, b"1.0", b""][:2]
        if len(request) < _MECHANISM_FRAMES:
            return [version, request_id, b"400", b"malformed ZAP request", b"", b""]
        domain, address, mechanism = request[2], request[3], request[5]
        if domain != ZAP_DOMAIN.encode():
            return [version, request_id, b"200", b"OK", b"", b""]
        if mechanism == b"PLAIN" and len(request) >= _PLAIN_FRAMES:
            user_ok = hmac.compare_digest(request[6], self._user)
            if hmac.compare_digest(request[7], self._password) and user_ok:
                return [version, request_id, b"200", b"OK", request[6], b""]
        self._refuse(address.decode(errors="replace"))
        return [version, request_id, b"400", b"Invalid username or password", b"", b""]

    def _refuse(self, address: str) -> None:
        self.refused += 1
        if self._count is not None:
            self._count("auth_failures")
        if self._warning.ready():
            _LOG.warning(
                "refused a subscriber from %s: wrong or missing credentials "
                "(GZ_TRANSPORT_USERNAME/PASSWORD; %d refused so far)",
                address,
                self.refused,
            )

    def close(self) -> None:
        self.socket.close(linger=0)

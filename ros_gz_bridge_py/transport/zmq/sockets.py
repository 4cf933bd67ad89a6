"""The sockets of one ZeroMQ node (docs/protocol-zmq-discovery.md §2.1), opened and released
together."""

from __future__ import annotations

import contextlib
import socket
import threading
import uuid
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import zmq

from ros_gz_bridge_py.errors import TransportError
from ros_gz_bridge_py.transport.settings import TransportSettings
from ros_gz_bridge_py.transport.zmq.auth import ZAP_DOMAIN, ZapHandler
from ros_gz_bridge_py.transport.zmq.connections import MAX_BACKOFF
from ros_gz_bridge_py.transport.zmq.udp import DiscoverySocket


@dataclass
class NodeSockets:
    """Two UDP discovery sockets, the five ZMQ sockets, and a socket pair to wake the I/O
    thread. The PUB socket is shared by publishing threads under ``pub_lock``."""

    context: Any
    msg_udp: DiscoverySocket
    srv_udp: DiscoverySocket
    pub: Any
    sub: Any
    replier: Any
    requester: Any
    responses: Any
    replier_id: str
    response_id: str
    wake_r: socket.socket
    wake_w: socket.socket
    #: The ZAP handler when authentication is on (GZ_TRANSPORT_USERNAME/PASSWORD).
    zap: ZapHandler | None = None
    pub_lock: threading.Lock = field(default_factory=threading.Lock)

    @property
    def host(self) -> str:
        """The interface discovery uses; the ZMQ sockets are bound to it."""
        return self.msg_udp.interface_ip

    def address(self, sock: Any) -> str:
        """The endpoint a bound socket advertises (``tcp://<host>:<port>``)."""
        endpoint: str = sock.getsockopt_string(zmq.LAST_ENDPOINT)
        return endpoint

    def wake(self) -> None:
        with contextlib.suppress(OSError):
            self.wake_w.send(b"\0")

    def release(self) -> None:
        with self.pub_lock:
            for udp in (self.msg_udp, self.srv_udp):
                udp.close()
            self.context.destroy(linger=0)
        self.wake_r.close()
        self.wake_w.close()


def open_sockets(
    settings: TransportSettings, host: str, count: Callable[..., None] | None = None
) -> NodeSockets:
    """Every socket of a node, bound on ``host`` (``count``: the node's counters, for the ZAP
    handler).

    Raises:
        TransportError: a socket cannot be opened (nothing is left open).
    """
    context = zmq.Context(io_threads=1)
    wake_r, wake_w = socket.socketpair()
    opened: list[DiscoverySocket] = []
    try:
        for port in (settings.msg_port, settings.srv_port):
            opened.append(DiscoverySocket(settings.multicast_ip, port, host))
        host = opened[0].interface_ip
        zap = (
            None
            if settings.credentials is None
            else ZapHandler(context, settings.credentials, count)
        )
        replier_id, response_id = str(uuid.uuid4()), str(uuid.uuid4())
        sockets = NodeSockets(
            context=context,
            msg_udp=opened[0],
            srv_udp=opened[1],
            pub=publisher_socket(context, host, settings, settings.sndhwm),
            sub=subscriber_socket(context, settings),
            replier=_bound(context, host, zmq.ROUTER, routing_id=replier_id, mandatory=True),
            requester=_socket(context, zmq.ROUTER, mandatory=True),
            responses=_bound(context, host, zmq.ROUTER, routing_id=response_id),
            replier_id=replier_id,
            response_id=response_id,
            wake_r=wake_r,
            wake_w=wake_w,
            zap=zap,
        )
        for sock in (sockets.replier, sockets.requester, sockets.responses):
            limit_input(sock, settings)
    except (OSError, zmq.ZMQError) as error:
        for udp in opened:
            udp.close()
        context.destroy(linger=0)
        wake_r.close()
        wake_w.close()
        msg = f"cannot open the Gazebo Transport sockets on {host}: {error}"
        raise TransportError(msg) from error
    wake_r.setblocking(False)
    wake_w.setblocking(False)
    return sockets


def limit_input(sock: Any, settings: TransportSettings) -> None:
    """Refuse frames over the maximum message size before they are buffered
    (docs/protocol-zmq-data.md §2.8.7), and retry an address that failed with a growing delay, up to
    MAX_BACKOFF."""
    sock.setsockopt(zmq.MAXMSGSIZE, settings.max_message_size)
    sock.setsockopt(zmq.RECONNECT_IVL_MAX, int(MAX_BACKOFF * 1000))


def subscriber_socket(context: Any, settings: TransportSettings, rcvhwm: int | None = None) -> Any:
    """A SUB socket: RCVHWM (``settings``' unless given), the size limit, and a PLAIN client
    with credentials (§2.8.6)."""
    sock = _socket(context, zmq.SUB, rcvhwm=settings.rcvhwm if rcvhwm is None else rcvhwm)
    limit_input(sock, settings)
    if settings.credentials is not None:
        user, password = settings.credentials
        sock.setsockopt(zmq.PLAIN_USERNAME, user.encode())
        sock.setsockopt(zmq.PLAIN_PASSWORD, password.encode())
    return sock


def publisher_socket(context: Any, host: str, settings: TransportSettings, sndhwm: int) -> Any:
    """A PUB socket bound on ``host`` with SNDHWM ``sndhwm`` (0: libzmq's default): a PLAIN
    server in ZAP domain ``gz-auth`` with credentials (§2.8.6); the ZAP handler (``auth.py``)
    must be bound before, or libzmq lets everyone in. The node's own, and that of each
    publisher with a socket of its own. The mark is set before the bind and never after: the
    pipe of each subscriber takes it when it connects, and libzmq 4.3.5 mishandles a mark
    changed on a live socket (§2.8.8)."""
    sock = _socket(context, zmq.PUB)
    if sndhwm:
        sock.setsockopt(zmq.SNDHWM, sndhwm)
    if settings.credentials is not None:
        sock.setsockopt(zmq.ZAP_DOMAIN, ZAP_DOMAIN.encode())
        sock.setsockopt(zmq.PLAIN_SERVER, 1)
    sock.bind(f"tcp://{host}:*")
    return sock


def _socket(
    context: Any, kind: int, *, rcvhwm: int = 0, routing_id: str = "", mandatory: bool = False
) -> Any:
    sock = context.socket(kind)
    sock.setsockopt(zmq.LINGER, 0)
    if rcvhwm:
        sock.setsockopt(zmq.RCVHWM, rcvhwm)
    if routing_id:
        sock.setsockopt(zmq.ROUTING_ID, routing_id.encode())
    if mandatory:
        sock.setsockopt(zmq.ROUTER_MANDATORY, 1)
    return sock


def _bound(
    context: Any,
    host: str,
    kind: int,
    *,
    sndhwm: int = 0,
    routing_id: str = "",
    mandatory: bool = False,
) -> Any:
    sock = _socket(context, kind, routing_id=routing_id, mandatory=mandatory)
    if sndhwm:
        sock.setsockopt(zmq.SNDHWM, sndhwm)
    sock.bind(f"tcp://{host}:*")
    return sock

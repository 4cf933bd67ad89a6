"""The sockets of one ZeroMQ node (docs/protocol.md §2.1), opened and released together."""

from __future__ import annotations

import contextlib
import socket
import threading
import uuid
from dataclasses import dataclass, field
from typing import Any

import zmq

from ros_gz_bridge_py.errors import TransportError
from ros_gz_bridge_py.transport.settings import TransportSettings
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


def open_sockets(settings: TransportSettings, host: str) -> NodeSockets:
    """Every socket of a node, bound on ``host``.

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
        replier_id, response_id = str(uuid.uuid4()), str(uuid.uuid4())
        sockets = NodeSockets(
            context=context,
            msg_udp=opened[0],
            srv_udp=opened[1],
            pub=_bound(context, host, zmq.PUB, sndhwm=settings.sndhwm),
            sub=_socket(context, zmq.SUB, rcvhwm=settings.rcvhwm),
            replier=_bound(context, host, zmq.ROUTER, routing_id=replier_id, mandatory=True),
            requester=_socket(context, zmq.ROUTER, mandatory=True),
            responses=_bound(context, host, zmq.ROUTER, routing_id=response_id),
            replier_id=replier_id,
            response_id=response_id,
            wake_r=wake_r,
            wake_w=wake_w,
        )
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

"""UDP sockets for multicast discovery (docs/protocol-zmq-discovery.md §2.2).

One socket per discovery port serves as receiver and sender. Like gz-transport it sets
SO_REUSEADDR and SO_REUSEPORT (several gz processes share the port), binds INADDR_ANY:port,
joins the group on the chosen interface and sends with IP_MULTICAST_IF set to it. With
GZ_IP=127.0.0.1 this works on a loopback without the MULTICAST flag, as real ign does.
"""

from __future__ import annotations

import contextlib
import errno
import logging
import socket

from ros_gz_bridge_py.errors import TransportError

_LOG = logging.getLogger("ros_gz_bridge_py.transport")
LOOPBACK = "127.0.0.1"
#: Send errors gz-transport ignores (§2.2.1).
_IGNORED_SEND_ERRORS = (errno.EPERM, errno.ENOBUFS)


def determine_host(configured_ip: str | None, group: str) -> str:
    """GZ_IP if set; else the address the kernel would send multicast from; else loopback.

    gz picks among all multicast-capable interfaces (§2.2.2); we use the route to the group,
    which is that interface on a single-homed host. Connecting a UDP socket sends nothing.
    """
    if configured_ip:
        return configured_ip
    probe = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    try:
        probe.connect((group, 9))
        address: str = probe.getsockname()[0]
    except OSError:
        address = LOOPBACK
    finally:
        probe.close()
    return address if address != "0.0.0.0" else LOOPBACK  # noqa: S104 - a result, not a bind


class DiscoverySocket:
    """The multicast socket of one discovery port."""

    def __init__(self, group: str, port: int, interface_ip: str) -> None:
        self.group = group
        self.port = port
        self.sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM, socket.IPPROTO_UDP)
        try:
            self.sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
            self.sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEPORT, 1)
            self.sock.bind(("", port))
            self.interface_ip = self._join(interface_ip)
            self.sock.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_LOOP, 1)
            self.sock.setblocking(False)
        except OSError as error:
            self.sock.close()
            msg = f"cannot open the discovery socket on UDP port {port}: {error}"
            raise TransportError(msg) from error

    def _join(self, interface_ip: str) -> str:
        """Join the group on ``interface_ip``, falling back to loopback like gz (§2.2.1)."""
        for candidate in dict.fromkeys((interface_ip, LOOPBACK)):
            try:
                interface = socket.inet_aton(candidate)
                self.sock.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_IF, interface)
                membership = socket.inet_aton(self.group) + interface
                self.sock.setsockopt(socket.IPPROTO_IP, socket.IP_ADD_MEMBERSHIP, membership)
            except OSError as error:
                _LOG.warning("cannot join %s on %s: %s", self.group, candidate, error)
                continue
            return candidate
        msg = f"cannot join multicast group {self.group} on {interface_ip} or {LOOPBACK}"
        raise OSError(msg)

    def fileno(self) -> int:
        """The file descriptor, for the poller."""
        return self.sock.fileno()

    def receive(self) -> tuple[bytes, str] | None:
        """One pending datagram and its source IP, or None if nothing is pending."""
        try:
            data, source = self.sock.recvfrom(65536)
        except (BlockingIOError, InterruptedError):
            return None
        return data, source[0]

    def send(self, data: bytes, relay_ip: str | None) -> bool:
        """Send to the group (or to ``relay_ip``); False if the kernel refused it."""
        destination = (relay_ip or self.group, self.port)
        try:
            self.sock.sendto(data, destination)
        except OSError as error:
            if error.errno not in _IGNORED_SEND_ERRORS:
                _LOG.debug("discovery send to %s failed: %s", destination, error)
                return False
        return True

    def close(self) -> None:
        """Close the socket; idempotent."""
        with contextlib.suppress(OSError):
            self.sock.close()

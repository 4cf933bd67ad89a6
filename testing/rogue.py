"""Hostile and fake Gazebo Transport peers for the hygiene tests, written with raw pyzmq and
raw UDP datagrams.

Everything stays on this host: datagrams go to the discovery group with TTL 0 through the
loopback interface (``GZ_IP`` of tests/conftest.py), sockets bind 127.0.0.1. Every peer is
bounded: it sends only what a test asks for, and its heartbeat thread stops with it (and
after :data:`MAX_LIFE` seconds at the latest).
"""

from __future__ import annotations

import selectors
import socket
import threading
import time
import uuid
from collections.abc import Sequence
from dataclasses import replace
from typing import Any

import zmq

from ros_gz_bridge_py.errors import RemoteProtocolError
from ros_gz_bridge_py.transport.api import Scope
from ros_gz_bridge_py.transport.settings import TransportSettings
from ros_gz_bridge_py.transport.zmq.udp import DiscoverySocket
from ros_gz_bridge_py.transport.zmq.wire import (
    DiscoveryMessage,
    DiscoveryType,
    MessagePublisher,
    PublisherRecord,
    decode_discovery,
    encode_discovery,
)

#: The longest a fake peer heartbeats, whatever the test does (s).
MAX_LIFE = 60.0


def discovery_socket() -> socket.socket:
    """A UDP socket that multicasts to the discovery group on this host only (TTL 0)."""
    settings = TransportSettings.from_env()
    sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    sock.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_TTL, 0)
    sock.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_LOOP, 1)
    sock.setsockopt(
        socket.IPPROTO_IP, socket.IP_MULTICAST_IF, socket.inet_aton(settings.ip or "127.0.0.1")
    )
    return sock


class FakePeer:
    """A process that exists only as discovery datagrams: it advertises ``records`` once a
    second with a heartbeat, until :meth:`go_silent` (no BYE: it just stops, like a crash)."""

    def __init__(self, fqn: str, msg_type: str, addresses: Sequence[str]) -> None:
        self.process_uuid = str(uuid.uuid4())
        kind = MessagePublisher(msg_type)
        self.records = [
            PublisherRecord(fqn, address, self.process_uuid, str(uuid.uuid4()), Scope.ALL, kind)
            for address in addresses
        ]
        self._settings = TransportSettings.from_env()
        self._sock = discovery_socket()
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, name="fake-peer", daemon=True)
        self._thread.start()

    def _send(self, kind: DiscoveryType, record: PublisherRecord | None = None) -> None:
        data = encode_discovery(DiscoveryMessage(kind, self.process_uuid, pub=record))
        self._sock.sendto(data, (self._settings.multicast_ip, self._settings.msg_port))

    def _run(self) -> None:
        end = time.monotonic() + MAX_LIFE
        while not self._stop.is_set() and time.monotonic() < end:
            self._send(DiscoveryType.HEARTBEAT)
            for index, record in enumerate(self.records):
                self._send(DiscoveryType.ADVERTISE, record)
                if index % 50 == 49:
                    time.sleep(0.002)  # let receivers drain instead of overflowing
            self._stop.wait(1.0)

    def unadvertise(self) -> None:
        """Withdraw every record, as a publisher that exits does (it heartbeats on)."""
        for record in self.records:
            self._send(DiscoveryType.UNADVERTISE, record)
        self.records = []

    def go_silent(self) -> None:
        self._stop.set()
        self._thread.join()
        self._sock.close()


class RoguePublisher:
    """A raw XPUB bound on loopback, advertised by a :class:`FakePeer`: it sees each
    subscription (a connection's filter), so a test can send one frame per connection."""

    def __init__(self, fqn: str, msg_type: str, *, sndhwm: int = 100) -> None:
        self.fqn = fqn
        self.msg_type = msg_type
        self.context = zmq.Context()
        self.xpub = self.context.socket(zmq.XPUB)
        self.xpub.setsockopt(zmq.LINGER, 0)
        self.xpub.setsockopt(zmq.XPUB_VERBOSE, 1)
        self.xpub.setsockopt(zmq.SNDHWM, sndhwm)
        self.xpub.bind("tcp://127.0.0.1:*")
        self.address: str = self.xpub.getsockopt_string(zmq.LAST_ENDPOINT)
        self.peer = FakePeer(fqn, msg_type, [self.address])
        self.subscriptions = 0

    def wait_subscribed(self, timeout: float) -> bool:
        """Wait for the next subscription message (a new or renewed connection's filter);
        unsubscriptions (a connection gone) are skipped."""
        deadline = time.monotonic() + timeout
        while (remaining := deadline - time.monotonic()) > 0:
            if not self.xpub.poll(int(remaining * 1000) + 1):
                return False
            subscribed = False
            while self.xpub.poll(0):
                if self.xpub.recv()[:1] == b"\x01":
                    self.subscriptions += 1
                    subscribed = True
            if subscribed:
                return True
        return False

    def send(self, payload: bytes | memoryview, msg_type: str | None = None) -> None:
        """One data message of four frames (docs/protocol-zmq-data.md §2.8.2), payload not
        copied."""
        self.xpub.send(self.fqn.encode(), zmq.SNDMORE)
        self.xpub.send(self.address.encode(), zmq.SNDMORE)
        self.xpub.send(payload, zmq.SNDMORE, copy=False)
        self.xpub.send((msg_type or self.msg_type).encode())

    def send_frames(self, frames: Sequence[bytes]) -> None:
        self.xpub.send_multipart(list(frames))

    def close(self) -> None:
        self.peer.go_silent()
        self.context.destroy(linger=0)


class RogueSubscriber:
    """A raw SUB socket that subscribes to ``fqn`` through valid discovery (SUBSCRIBE, then a
    NEW_CONNECTION for each publisher of ``msg_type`` it hears advertised, and heartbeats) and
    never reads. Its own queue holds one message (RCVHWM 1, a 4 kB kernel buffer), so what the
    publisher sends past that stays queued in the publisher, as behind a slow or hostile peer.
    Everything runs on its thread, which stops with :meth:`close` (or after :data:`MAX_LIFE`).
    """

    def __init__(self, fqn: str, msg_type: str) -> None:
        self.fqn = fqn
        self.msg_type = msg_type
        self.process_uuid = str(uuid.uuid4())
        self.node_uuid = str(uuid.uuid4())
        self._settings = TransportSettings.from_env()
        self.context = zmq.Context()
        self.sub = self.context.socket(zmq.SUB)
        self.sub.setsockopt(zmq.LINGER, 0)
        self.sub.setsockopt(zmq.RCVHWM, 1)
        self.sub.setsockopt(zmq.RCVBUF, 4096)
        self.sub.setsockopt(zmq.SUBSCRIBE, fqn.encode())
        self._listen = DiscoverySocket(
            self._settings.multicast_ip, self._settings.msg_port, self._settings.ip or "127.0.0.1"
        )
        self._sock = discovery_socket()
        #: The publisher addresses it connected to.
        self.connected: list[str] = []
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, name="rogue-sub", daemon=True)
        self._thread.start()

    def _send(self, message: DiscoveryMessage) -> None:
        data = encode_discovery(message)
        self._sock.sendto(data, (self._settings.multicast_ip, self._settings.msg_port))

    def _run(self) -> None:
        end = time.monotonic() + MAX_LIFE
        next_beat = 0.0
        while not self._stop.is_set() and (now := time.monotonic()) < end:
            if now >= next_beat:
                self._send(DiscoveryMessage(DiscoveryType.HEARTBEAT, self.process_uuid))
                if not self.connected:
                    self._send(
                        DiscoveryMessage(DiscoveryType.SUBSCRIBE, self.process_uuid, topic=self.fqn)
                    )
                next_beat = now + 1.0
            received = self._listen.receive()
            if received is None:
                self._stop.wait(0.01)
                continue
            try:
                message = decode_discovery(received[0])
            except RemoteProtocolError:
                continue  # not ours to judge
            pub = message.pub
            if (
                message.type == DiscoveryType.ADVERTISE
                and pub is not None
                and pub.msg is not None
                and pub.topic == self.fqn
                and pub.msg_type == self.msg_type
                and pub.address not in self.connected
            ):
                self.sub.connect(pub.address)
                self.connected.append(pub.address)
                mine = replace(
                    pub,
                    process_uuid=self.process_uuid,
                    node_uuid=self.node_uuid,
                    msg=replace(pub.msg, ctrl=pub.process_uuid),
                )
                self._send(
                    DiscoveryMessage(DiscoveryType.NEW_CONNECTION, self.process_uuid, pub=mine)
                )

    def close(self) -> None:
        self._stop.set()
        self._thread.join()
        self._send(DiscoveryMessage(DiscoveryType.BYE, self.process_uuid))
        self._listen.close()
        self._sock.close()
        self.context.destroy(linger=0)


class TrapListeners:
    """``count`` TCP listeners on 127.0.0.1 that accept each connection, count it and close it
    at once: to libzmq a failed connection, retried like a refused one, but one we can count."""

    def __init__(self, count: int) -> None:
        self._selector = selectors.DefaultSelector()
        self.listeners = []
        for _ in range(count):
            sock = socket.socket()
            sock.bind(("127.0.0.1", 0))
            sock.listen(16)
            sock.setblocking(False)
            self._selector.register(sock, selectors.EVENT_READ)
            self.listeners.append(sock)
        self.accepted = 0
        self._lock = threading.Lock()
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, name="trap", daemon=True)
        self._thread.start()

    @property
    def addresses(self) -> list[str]:
        return [f"tcp://127.0.0.1:{sock.getsockname()[1]}" for sock in self.listeners]

    def _run(self) -> None:
        while not self._stop.is_set():
            for key, _ in self._selector.select(0.1):
                listener: Any = key.fileobj
                try:
                    conn, _ = listener.accept()
                except OSError:
                    continue
                conn.close()
                with self._lock:
                    self.accepted += 1

    def close(self) -> None:
        self._stop.set()
        self._thread.join()
        for sock in self.listeners:
            sock.close()
        self._selector.close()


def closed_ports(count: int) -> list[str]:
    """``count`` addresses on 127.0.0.1 where nothing listens (bound, then released)."""
    socks = []
    for _ in range(count):
        sock = socket.socket()
        sock.bind(("127.0.0.1", 0))
        socks.append(sock)
    addresses = [f"tcp://127.0.0.1:{sock.getsockname()[1]}" for sock in socks]
    for sock in socks:
        sock.close()
    return addresses

"""Malformed input from the network never stops a node; it is counted.

The node gets discovery ports of its own (unicast to a shared port would reach other
processes), and a bounded number of bad datagrams and ZMQ messages on loopback.
"""

from __future__ import annotations

import random
import socket
import time
from collections.abc import Callable

import zmq

from ros_gz_bridge_py.transport import TransportSettings
from ros_gz_bridge_py.transport.api import Scope
from ros_gz_bridge_py.transport.zmq.node import ZmqGzNode
from ros_gz_bridge_py.transport.zmq.wire import (
    DiscoveryMessage,
    DiscoveryType,
    MessagePublisher,
    PublisherRecord,
    encode_discovery,
)
from testing.polling import wait_until

COUNT = 2000


def free_udp_port_pair() -> int:
    while True:
        with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as probe:
            probe.bind(("127.0.0.1", 0))
            port: int = probe.getsockname()[1]
        if port < 65000:
            return port


def bad_datagrams(rng: random.Random, fqn: str) -> list[bytes]:
    good = encode_discovery(
        DiscoveryMessage(
            DiscoveryType.ADVERTISE, "fuzz-process",
            pub=PublisherRecord(fqn, "not-an-endpoint", "fuzz-process", "n", Scope.ALL,
                                MessagePublisher("gz.msgs.StringMsg")),
        )
    )  # fmt: skip
    kinds: list[Callable[[], bytes]] = [
        lambda: rng.randbytes(rng.randrange(0, 600)),
        lambda: good[: rng.randrange(0, len(good))],
        lambda: good[:2] + b"\x10" + bytes([rng.choice([8, 9, 11, 110])]) + good[4:],
        lambda: rng.randbytes(2) + good[2:],
        lambda: len(body := rng.randbytes(rng.randrange(1, 300))).to_bytes(2, "little") + body,
        lambda: b"\x04\x00\x10\x0a\x20" + bytes([rng.randrange(10, 120)]),
    ]
    return [kinds[i % len(kinds)]() for i in range(COUNT)] + [good]


def test_fuzzed_node_keeps_working() -> None:
    port = free_udp_port_pair()
    settings = TransportSettings(
        partition=f"fuzz-{port}", ip="127.0.0.1", msg_port=port, srv_port=port + 1
    )
    rng = random.Random(1234)
    with ZmqGzNode(settings=settings) as victim:
        victim.subscribe("/fuzzed", lambda *_: None)
        with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as attacker:
            for index, data in enumerate(bad_datagrams(rng, f"@/fuzz-{port}@/fuzzed")):
                if index % 50 == 0:
                    time.sleep(0.002)  # pacing so the receive buffer does not overflow
                attacker.sendto(data, ("127.0.0.1", port))
                attacker.sendto(data, ("127.0.0.1", port + 1))
        # Malformed ZMQ messages: a 3-frame service request.
        context = zmq.Context()
        dealer = context.socket(zmq.DEALER)
        dealer.setsockopt(zmq.LINGER, 0)
        dealer.connect(victim.replier_address)
        dealer.send_multipart([b"a", b"b", b"c"])
        assert wait_until(lambda: victim.stats.frames_malformed >= 1)
        dealer.close()
        context.term()
        assert wait_until(lambda: victim.stats.datagrams_received >= COUNT // 2)
        stats = victim.stats
        assert stats.datagrams_malformed > 0
        assert stats.datagrams_wrong_version > 0
        assert stats.unknown_types > 0
        assert stats.io_errors == 0

        # Still a working participant.
        with ZmqGzNode(settings=settings) as other:
            got: list[bytes] = []
            victim.subscribe("/after", lambda data, _: got.append(data))
            pub = other.advertise("/after", "gz.msgs.StringMsg")
            assert wait_until(pub.has_connections)
            # Repeat: the first message may beat the SUB's TCP handshake (ZMQ slow joiner).
            for _ in range(500):
                if got:
                    break
                pub.publish_raw(b"\x12\x02ok")
                time.sleep(0.02)
            assert got[0] == b"\x12\x02ok"

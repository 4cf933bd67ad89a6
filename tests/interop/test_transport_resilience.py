"""Our node keeps working with the real peer after a publisher crash or discovery garbage."""

from __future__ import annotations

import os
import random
import socket
import struct
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

from ros_gz_bridge_py.msgs import message_class
from ros_gz_bridge_py.transport.settings import TransportSettings
from testing.gzpeer import Inbox, start_peer, unique_name, wait_for_line, wait_until

pytestmark = pytest.mark.peer

STRING = "ignition.msgs.StringMsg"
WIRE_VERSION = 10
ADVERTISE = 1


def has_data(text: str) -> Any:
    """An Inbox condition: some StringMsg with ``data == text`` arrived."""
    return lambda items: any(msg.data == text for msg, _ in items)


def test_subscriber_recovers_when_the_publisher_is_killed_and_restarted(
    ign_peer: Path, gz_node: Any
) -> None:
    topic = unique_name("restart")
    inbox = Inbox()
    gz_node.subscribe_typed(topic, message_class(STRING), inbox, msg_type=STRING)

    first = start_peer("pub", topic, STRING, "20", "0", 'data: "first"')
    wait_for_line(first, r"^CONNECTED$")
    inbox.wait_for(has_data("first"), 5, "a message of the first publisher")
    first.kill()  # SIGKILL: no UNADVERTISE, no BYE
    first.wait()
    inbox.clear()

    second = start_peer("pub", topic, STRING, "20", "0", 'data: "second"')
    # The peer waits up to 5 s for our NEW_CONNECTION before it says CONNECTED.
    assert wait_for_line(second, r"^(CONNECTED|NO_CONNECTIONS)$")[1] == "CONNECTED"
    items = inbox.wait_for(has_data("second"), 5, "a message of the restarted publisher")

    assert {msg.data for msg, _ in items} <= {"first", "second"}


def framed(body: bytes) -> bytes:
    """A discovery datagram: little-endian uint16 length, then the body
    (docs/protocol-zmq-discovery.md §2.3)."""
    return struct.pack("<H", len(body)) + body


def discovery(version: int, topic: str = "", address: str = "") -> bytes:
    """A Discovery message; with ``topic`` an ADVERTISE carrying ``address``."""
    message = message_class("ignition.msgs.Discovery")(
        version=version, process_uuid="00000000-0000-0000-0000-00000000dead"
    )
    if topic:
        message.type = ADVERTISE
        message.pub.topic = topic
        message.pub.address = address
        message.pub.process_uuid = message.process_uuid
        message.pub.node_uuid = message.process_uuid
        message.pub.msg_pub.msg_type = STRING
    data: bytes = message.SerializeToString()
    return data


def junk_datagrams(fq_topic: str, per_kind: int) -> Iterator[bytes]:
    """Malformed and hostile discovery datagrams, ``per_kind`` of each kind."""
    rng = random.Random(7)
    for _ in range(per_kind):
        yield b""
        yield b"\x05"
        yield rng.randbytes(rng.randrange(2, 300))  # length prefix does not match
        yield framed(rng.randbytes(rng.randrange(1, 300)))  # not a Discovery message
        yield framed(b"\xff" * 40)  # truncated varints
        yield struct.pack("<H", 60000) + rng.randbytes(100)  # claims more than it has
        yield framed(discovery(WIRE_VERSION - 1))  # wrong version
        yield framed(discovery(WIRE_VERSION, fq_topic, "not-an-endpoint"))
        yield framed(discovery(WIRE_VERSION, fq_topic, "tcp://127.0.0.1:1"))


def flood_discovery(datagrams: Iterator[bytes]) -> int:
    """Multicast ``datagrams`` on the message discovery port; TTL 0 keeps them on this host."""
    settings = TransportSettings.from_env()
    sent = 0
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as sock:
        sock.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_TTL, 0)
        sock.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_LOOP, 1)
        sock.setsockopt(
            socket.IPPROTO_IP, socket.IP_MULTICAST_IF, socket.inet_aton(settings.ip or "127.0.0.1")
        )
        for datagram in datagrams:
            sock.sendto(datagram, (settings.multicast_ip, settings.msg_port))
            sent += 1
            if sent % 100 == 0:
                time.sleep(0.005)  # let the receiver drain instead of overflowing its buffer
    return sent


def test_node_survives_a_flood_of_malformed_discovery_datagrams(
    ign_peer: Path, gz_node: Any
) -> None:
    topic = unique_name("after_flood")
    partition = os.environ["IGN_PARTITION"]
    inbox = Inbox()
    gz_node.subscribe_typed(topic, message_class(STRING), inbox, msg_type=STRING)
    publisher = gz_node.advertise(topic + "_back", STRING)

    # Before any real peer starts: the hostile ADVERTISEs name the real peer's topic too.
    assert flood_discovery(junk_datagrams(f"@/{partition}@{topic}", per_kind=100)) == 900
    wait_until(
        lambda: gz_node.stats.datagrams_malformed > 0 and gz_node.stats.datagrams_wrong_version > 0,
        10,
        "the node to count the junk",
    )

    peer = start_peer("pub", topic, STRING, "20", "10", 'data: "still here"')
    wait_for_line(peer, r"^CONNECTED$")
    items = inbox.wait_for(has_data("still here"), 5, "the real publisher's messages")
    assert {msg.data for msg, _ in items} == {"still here"}

    echo = start_peer("echo", topic + "_back", STRING, "20", "--count", "1")
    wait_for_line(echo, r"^READY$")
    wait_until(publisher.has_connections, 10, "the C++ echo to connect")
    deadline = time.monotonic() + 10
    while echo.poll() is None and time.monotonic() < deadline:
        publisher.publish(message_class(STRING)(data="back"))
        time.sleep(0.05)
    wait_for_line(echo, rf'^MSG {STRING} data: "back"$')

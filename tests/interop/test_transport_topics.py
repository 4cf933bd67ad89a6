"""Topics between our node and real Ignition Transport 11 processes, both directions.

Each case uses a topic name of its own, waits for discovery (CONNECTED / has_connections)
before publishing, and checks the values that arrived.
"""

from __future__ import annotations

import re
import time
from pathlib import Path
from typing import Any

import pytest

from ros_gz_bridge_py.msgs import message_class
from ros_gz_bridge_py.msgs.names import Spelling, respell, spellings
from testing.gzpeer import (
    IGN_TOPIC,
    Inbox,
    ign_topic,
    start_peer,
    start_process,
    unique_name,
    wait_for_line,
    wait_until,
)

pytestmark = pytest.mark.peer

STRING = "ignition.msgs.StringMsg"
LOOPBACK_ADDRESS = r"tcp://127\.0\.0\.1:\d+"
#: One-shots the CLI test makes at most, and how long each may take to arrive.
ONE_SHOT_ATTEMPTS, ONE_SHOT_WAIT = 10, 2.0


def publish_until(publisher: Any, done: Any, what: str, timeout: float = 10.0) -> list[str]:
    """Publish StringMsg ``m0``, ``m1``, ... at 20 Hz until ``done()``; returns the values sent.

    A real subscriber's ZeroMQ connection can come up just after discovery says it exists, so
    the first messages may miss it; the receiver then gets a consecutive run of values.
    """
    string_msg = message_class(STRING)
    sent: list[str] = []
    deadline = time.monotonic() + timeout
    while not done():
        if time.monotonic() > deadline:
            pytest.fail(f"timed out after {timeout} s publishing until {what}")
        sent.append(f"m{len(sent)}")
        publisher.publish(string_msg(data=sent[-1]))
        time.sleep(0.05)
    return sent


def assert_consecutive(received: list[str], sent: list[str]) -> None:
    """``received`` is a run of consecutive values out of ``sent``, in order."""
    assert received, "nothing received"
    start = sent.index(received[0])
    assert received == sent[start : start + len(received)]


def test_our_subscriber_receives_the_cpp_publisher(ign_peer: Path, gz_node: Any) -> None:
    topic = unique_name("cpp_to_py")
    inbox = Inbox()
    gz_node.subscribe_typed(topic, message_class(STRING), inbox, msg_type=STRING)

    peer = start_peer("pub", topic, STRING, "20", "10", 'data: "hello from C++"')
    wait_for_line(peer, r"^CONNECTED$")
    wait_for_line(peer, r"^SENT 10$")
    items = inbox.wait_for_count(10, timeout=5)

    assert [msg.data for msg, _ in items] == ["hello from C++"] * 10
    for _, info in items:
        assert info.topic == topic
        assert info.msg_type == STRING
        assert re.fullmatch(LOOPBACK_ADDRESS, info.publisher_address)
        assert not info.intra_process


def test_our_subscriber_receives_a_one_shot_cli_publish(ign_peer: Path, gz_node: Any) -> None:
    """The CLI publishes once, 800 ms after advertising, and only if it knows of a subscriber
    by then. Under load ign-transport 11 itself sometimes never sends that message (a C++
    subscriber missed it in 3 of 14 runs here, a raw ZeroMQ SUB on the CLI's endpoint saw
    nothing either; with two busy loops beside the suite, six one-shots in a row once did), so
    up to ONE_SHOT_ATTEMPTS one-shots are made. A one-shot that arrives late, while the next is
    awaited, still counts: each message must be one of those sent, whole and once.
    """
    topic = unique_name("cli_once")
    inbox = Inbox()
    gz_node.subscribe_typed(topic, message_class(STRING), inbox, msg_type=STRING)

    sent: list[str] = []
    for attempt in range(1, ONE_SHOT_ATTEMPTS + 1):
        sent.append(f"hi {attempt}")
        done = ign_topic("-t", topic, "-m", STRING, "-p", f'data:"{sent[-1]}"', timeout=10)
        assert done.returncode == 0, done.stdout
        if inbox.holds_within(lambda items: len(items) > 0, ONE_SHOT_WAIT):
            break
    items = inbox.wait_for_count(1, timeout=1)

    received = [message.data for message, _ in items]
    assert set(received) <= set(sent), received
    assert len(set(received)) == len(received), received
    assert all(info.msg_type == STRING for _, info in items)


def test_cli_echo_receives_our_publisher(ign_peer: Path, gz_node: Any) -> None:
    topic = unique_name("py_to_cli")
    publisher = gz_node.advertise(topic, STRING)
    echo = start_process([str(IGN_TOPIC), "-e", "-t", topic, "-n", "3"])
    wait_until(publisher.has_connections, 10, "the CLI echo to connect")

    sent = publish_until(publisher, lambda: echo.poll() is not None, "the CLI echo printed 3")
    received = re.findall(r'data: "(m\d+)"', echo.output())

    assert echo.returncode == 0, echo.output()
    assert len(received) == 3
    assert_consecutive(received, sent)


def test_cpp_echo_receives_our_publisher(ign_peer: Path, gz_node: Any) -> None:
    topic = unique_name("py_to_cpp")
    publisher = gz_node.advertise(topic, STRING)
    echo = start_peer("echo", topic, STRING, "20", "--count", "5")
    wait_for_line(echo, r"^READY$")
    wait_until(publisher.has_connections, 10, "the C++ echo to connect")

    sent = publish_until(publisher, lambda: echo.poll() is not None, "the C++ echo got 5")
    output = echo.output()
    received = re.findall(rf'^MSG {re.escape(STRING)} data: "(m\d+)"$', output, re.MULTILINE)

    assert "COUNT 5 BYTES" in output
    assert len(received) == 5
    assert_consecutive(received, sent)


@pytest.mark.parametrize("advertised", [STRING, respell(STRING, Spelling.GZ)])
def test_cli_lists_our_publisher_with_type_and_address(
    ign_peer: Path, gz_node: Any, advertised: str
) -> None:
    """Advertised as gz.msgs, the ignition.msgs announcement is the second one: the CLI, which
    only listens for two heartbeats, hears it repeated once our node heard its heartbeat."""
    topic = unique_name("listed")
    gz_node.advertise(topic, advertised)

    listing = ign_topic("-l", timeout=10)
    info = ign_topic("-i", "-t", topic, timeout=10)

    assert topic in listing.stdout.split()
    # Announced under both spellings of its type (docs/protocol-lines.md §9.2), from one address;
    # each second again in the spellings the live peers use: the Fortress CLI's at least
    # (ignition.msgs; gz.msgs too while a peer of another line, or of none known yet, lives).
    rows = re.findall(rf"^\s+({LOOPBACK_ADDRESS}), (\S+)$", info.stdout, re.MULTILINE)
    types = {msg_type for _, msg_type in rows}
    assert STRING in types, info.stdout
    assert types <= set(spellings(STRING)), info.stdout
    (address,) = {address for address, _ in rows}
    ours = [row.address for row in gz_node.topic_info(topic)]
    assert ours == [address, address]


def test_round_trip_through_the_cpp_relay(ign_peer: Path, gz_node: Any) -> None:
    """Our publisher -> real subscriber + publisher in one C++ process -> our subscriber."""
    outbound, inbound = unique_name("relay_out"), unique_name("relay_back")
    inbox = Inbox()
    gz_node.subscribe_typed(inbound, message_class(STRING), inbox, msg_type=STRING)
    publisher = gz_node.advertise(outbound, STRING)
    relay = start_peer("relay", outbound, inbound, STRING, "30")
    wait_for_line(relay, r"^READY$")
    wait_until(publisher.has_connections, 10, "the relay to subscribe")

    sent = publish_until(publisher, lambda: len(inbox.items()) >= 3, "3 relayed messages")
    received = [msg.data for msg, _ in inbox.items()]

    assert_consecutive(received, sent)
    assert all(info.topic == inbound and not info.intra_process for _, info in inbox.items())

"""A 6 MB ignition.msgs.Bytes crosses between our node and the C++ peer intact, both ways.

Payloads are compared by SHA-256: the peer prints the digest of what it sent or received.
"""

from __future__ import annotations

import hashlib
import os
import time
from pathlib import Path
from typing import Any

import pytest

from ros_gz_bridge_py.msgs import message_class
from testing.gzpeer import Inbox, start_peer, unique_name, wait_for_line, wait_until

pytestmark = pytest.mark.peer

BYTES = "ignition.msgs.Bytes"
SIZE = 6_000_000


def test_six_megabytes_from_cpp(ign_peer: Path, gz_node: Any) -> None:
    topic = unique_name("big_cpp_to_py")
    inbox = Inbox()
    gz_node.subscribe(topic, inbox, BYTES)

    peer = start_peer("pub", topic, BYTES, "5", "3", "--bytes", str(SIZE))
    sent = wait_for_line(peer, r"^PAYLOAD sha256=(\w+) len=(\d+)$")
    wait_for_line(peer, r"^CONNECTED$")
    items = inbox.wait_for_count(3, timeout=15)

    for payload, info in items:
        assert info.msg_type == BYTES
        assert len(payload) == int(sent[2])
        assert hashlib.sha256(payload).hexdigest() == sent[1]
    assert len(message_class(BYTES).FromString(items[0][0]).data) == SIZE


def test_six_megabytes_to_cpp(ign_peer: Path, gz_node: Any) -> None:
    topic = unique_name("big_py_to_cpp")
    payload = message_class(BYTES)(data=os.urandom(SIZE)).SerializeToString()
    digest = hashlib.sha256(payload).hexdigest()
    publisher = gz_node.advertise(topic, BYTES)
    echo = start_peer("echo", topic, BYTES, "30", "--sha", "--count", "2")
    wait_for_line(echo, r"^READY$")
    wait_until(publisher.has_connections, 10, "the C++ echo to connect")

    deadline = time.monotonic() + 15
    while echo.poll() is None and time.monotonic() < deadline:
        publisher.publish_raw(payload)
        time.sleep(0.1)

    wait_for_line(echo, rf"^MSG {BYTES} sha256={digest} len={len(payload)}$")
    wait_for_line(echo, rf"^MSG {BYTES} sha256={digest} len={len(payload)}$")
    wait_for_line(echo, rf"^COUNT 2 BYTES {2 * len(payload)}$")

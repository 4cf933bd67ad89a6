"""Disconnecting from a real one-shot publisher without the libzmq abort.

A one-shot publisher (``ign topic -p``, here the C++ peer's ``pub`` with a count of 1, the
same ign-transport 11 code) advertises, publishes one message and exits (UNADVERTISE, BYE).
A SUB socket that polled (libzmq then holds the message's first frame) and disconnects on that
goodbye before reading aborts in fq.cpp (docs/protocol-zmq-data.md §2.8.7): that is why the node
never disconnected. Our node now disconnects from publishers that are gone, reading whole messages
first. Each case runs in a child process (``one_shot_child.py``), since the abort kills it.

The peer rather than ``ign topic -p``: the CLI publishes 800 ms after advertising whether or
not anyone is connected, and it exits as it publishes, so that about one message in four
never reaches the wire (docs/protocol-zmq-data.md §2.8.7); the peer publishes once its subscribers
are connected, then settles 1 s so that the child's plain SUB socket, connected just after the
node's, is up too.
"""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

from testing.gzpeer import PeerProcess, start_peer, start_process, unique_name, wait_for_line

pytestmark = pytest.mark.peer

STRING = "ignition.msgs.StringMsg"
ROOT = Path(__file__).resolve().parents[2]
#: One-shots made before giving up, should a connection come up later than the settling time.
ATTEMPTS = 3


def one_shot(mode: str) -> tuple[PeerProcess, str]:
    """Run the child in ``mode`` against a one-shot publisher until the message arrived;
    the child's process (ended) and its output."""
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    for attempt in range(ATTEMPTS):
        topic = unique_name(f"one_shot_{mode}")
        child = start_process(
            [sys.executable, "-m", "tests.interop.one_shot_child", mode, topic], env
        )
        wait_for_line(child, r"^READY$", timeout=10)
        publisher = start_peer(
            "pub", topic, STRING, "0", "1", f'data:"shot {attempt}"',
            "--wait", "10", "--settle", "1", "--linger", "0.3",
        )  # fmt: skip
        wait_for_line(publisher, r"^SENT 1$", timeout=15)
        try:
            child.wait(30)
        except subprocess.TimeoutExpired:
            child.stop()
        output = child.output()
        if "NO DATA" not in output:
            return child, output
    pytest.fail(f"no one-shot message was sent in {ATTEMPTS} attempts")


def test_a_plain_disconnect_after_a_poll_aborts_in_libzmq(ign_peer: Path) -> None:
    """The old crash, reproduced with a real ign-transport publisher: it must still be there,
    or this file no longer proves anything about our way."""
    child, output = one_shot("plain")
    assert child.returncode != 0, output
    assert "fq.cpp" in output


def test_our_node_disconnects_from_a_one_shot_publisher_and_lives(ign_peer: Path) -> None:
    """Both subscriptions (a queued one's own socket, and the shared socket) disconnect when
    the publisher says goodbye. Each usually gets the message; a socket whose connection came up
    after the one message was sent misses it (the slow joiner, docs/protocol-zmq-data.md §2.8.1)."""
    child, output = one_shot("ours")
    assert child.returncode == 0, output
    assert re.search(r"^RECEIVED [12]$", output, re.MULTILINE), output
    assert "DISCONNECTED 2" in output

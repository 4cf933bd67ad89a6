"""PLAIN authentication against the real Fortress peer (docs/protocol-zmq-data.md §2.8.6).

ign-transport 11 reads ``IGN_TRANSPORT_USERNAME``/``IGN_TRANSPORT_PASSWORD``; our node here
gets its credentials in its settings (the environment's ``GZ_``/``IGN_`` names give the same,
``test_settings.py``). With the same credentials messages flow both ways; with wrong or
missing ones on the C++ side nothing does, either way (discovery, which is not
authenticated, still works, so both sides try).
"""

from __future__ import annotations

import dataclasses
import os
import time
from collections.abc import Iterator
from pathlib import Path

import pytest

from ros_gz_bridge_py.msgs import message_class
from ros_gz_bridge_py.transport import TransportSettings
from ros_gz_bridge_py.transport.zmq.node import ZmqGzNode
from testing.gzpeer import Inbox, start_peer, unique_name, wait_for_line, wait_until

pytestmark = pytest.mark.peer

STRING = "ignition.msgs.StringMsg"
GzString = message_class(STRING)
OURS = ("robot", "s3cret")
#: How long "nothing flows" is watched (s): the matching case flows within a second.
QUIET = 3.0


@pytest.fixture
def node() -> Iterator[ZmqGzNode]:
    settings = dataclasses.replace(TransportSettings.from_env(), credentials=OURS)
    with ZmqGzNode(settings=settings) as gz_node:
        yield gz_node


def peer_env(credentials: tuple[str, str] | None) -> dict[str, str]:
    env = {k: v for k, v in os.environ.items() if "TRANSPORT_USERNAME" not in k}
    env = {k: v for k, v in env.items() if "TRANSPORT_PASSWORD" not in k}
    if credentials is not None:
        env["IGN_TRANSPORT_USERNAME"], env["IGN_TRANSPORT_PASSWORD"] = credentials
    return env


@pytest.mark.parametrize(
    ("theirs", "flows"), [(OURS, True), (("robot", "guess"), False), (None, False)]
)
def test_messages_flow_both_ways_only_with_the_same_credentials(
    ign_peer: Path, node: ZmqGzNode, theirs: tuple[str, str] | None, flows: bool
) -> None:
    env = peer_env(theirs)
    # Gazebo -> us
    topic_in = unique_name("auth_in")
    inbox = Inbox()
    node.subscribe_typed(topic_in, GzString, inbox, msg_type=STRING, queue_size=10)
    publisher = start_peer("pub", topic_in, STRING, "20", "0", 'data: "from ign"', env=env)
    wait_for_line(publisher, r"^READY$")
    arrived = inbox.holds_within(lambda items: len(items) > 0, 10.0 if flows else QUIET)
    assert arrived == flows
    publisher.stop()
    # us -> Gazebo
    topic_out = unique_name("auth_out")
    echo = start_peer("echo", topic_out, STRING, "15", "--count", "1", env=env)
    wait_for_line(echo, r"^READY$")
    ours = node.advertise(topic_out, STRING)
    wait_until(ours.has_connections, 10, "the C++ echo to subscribe (discovery is open)")
    deadline = time.monotonic() + (10.0 if flows else QUIET)
    while echo.poll() is None and time.monotonic() < deadline:
        ours.publish(GzString(data="from us"))
        time.sleep(0.05)
    echo.stop()
    got = [line for line in echo.output().splitlines() if line.startswith("MSG ")]
    assert bool(got) == flows, echo.output()
    if theirs is not None and not flows:
        assert node.stats.auth_failures > 0  # counted (and logged) on our side both ways

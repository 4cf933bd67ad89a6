"""What the native reader teaches its pump (transport/zmq/reader.py ``NativeReader._judge``):
routes from the topic's own frames only. The end-to-end case, with a real pump on real sockets,
is in test_pump_loop.py; fuzz/loop_fuzz.c checks every decision of the pump against this reader.
"""

from __future__ import annotations

from collections.abc import Iterator

import pytest

from tests.unit.native.loop_fuzz_host import FQN, Host, spellings

SENDER = b"tcp://127.0.0.1:40001"
GZ, IGNITION = spellings("gz.msgs.Pose_V")


class Learned:
    """A pump that records what it is taught."""

    def __init__(self) -> None:
        self.routes: list[tuple[bytes, bytes, bool]] = []

    def learn(self, sender: bytes, msg_type: bytes, take: bool) -> None:
        self.routes.append((sender, msg_type, take))


@pytest.fixture
def host() -> Iterator[Host]:
    found = Host()
    try:
        yield found
    finally:
        found.close()


@pytest.mark.parametrize(
    "topic", [FQN.encode() + b"_static", FQN.encode() + b"\xff"], ids=["static", "not-utf8"]
)
def test_a_topic_the_channel_prefixes_teaches_no_route(host: Host, topic: bytes) -> None:
    pump = Learned()
    host.reset(pump, [GZ, IGNITION])
    host.judge([topic, SENDER, b"", GZ])
    assert pump.routes == []
    host.judge([FQN.encode(), SENDER, b"", GZ])
    assert pump.routes == [(SENDER, GZ, True)]


def test_the_channels_own_frames_teach_their_routes(host: Host) -> None:
    pump = Learned()
    host.reset(pump, [GZ])
    host.judge([FQN.encode(), SENDER, b"", GZ])
    host.judge([FQN.encode(), SENDER, b"", IGNITION])  # not a type the topic takes: rejected
    host.judge([FQN.encode(), SENDER, b""])  # not a data message
    assert pump.routes == [(SENDER, GZ, True)]
    assert host.rejected == 2

"""Datagram and ZMQ frame codecs against golden bytes captured from ign-transport 11.0.0.

The layouts: docs/protocol-zmq-discovery.md §2.3, docs/protocol-zmq-data.md §2.8.2, §2.9; the
captures: §2.3.2.
"""

from __future__ import annotations

import pytest

from ros_gz_bridge_py.errors import RemoteProtocolError
from ros_gz_bridge_py.transport.api import Scope
from ros_gz_bridge_py.transport.zmq.wire import (
    UNTHROTTLED,
    DiscoveryMessage,
    DiscoveryType,
    MessagePublisher,
    PublisherRecord,
    ServicePublisher,
    ServiceRequest,
    ServiceResponse,
    UnknownMessageTypeError,
    decode_data,
    decode_discovery,
    decode_request,
    decode_response,
    encode_data,
    encode_discovery,
    encode_request,
    encode_response,
)

SUBSCRIBER = "8fac3557-a1af-460e-92b0-1c45be37ee4e"
PUBLISHER = "ce706bf2-4115-4b4c-9992-067a4b7ce765"
PUB_NODE = "0dc5e33d-fa13-4777-8aca-ba3f4b9de9fd"
SUB_NODE = "85da4ba5-614e-494c-a9bf-2e66c7c4f975"


def uuid_field(uuid: str) -> bytes:
    return b"\x1a\x24" + uuid.encode()


# frame 1 of the dump: length 42 | version 10 | process uuid | type 4
HEARTBEAT = b"\x2a\x00" + b"\x10\x0a" + uuid_field(SUBSCRIBER) + b"\x20\x04"
# frame 3: length 58 | version | uuid | type 2 | field 6 sub { topic }
SUBSCRIBE = (
    b"\x3a\x00\x10\x0a" + uuid_field(SUBSCRIBER) + b"\x20\x02" + b"\x32\x0e\x0a\x0c@/vm:root@/x"
)
# frame 5: ADVERTISE with pub { topic, address, uuids, scope ALL, msg_pub {...} }
ADVERTISE = bytes.fromhex(
    "ce00100a1a2463653730366266322d343131352d346234632d393939322d303637613462376365373635"
    "20013aa1010a0c402f766d3a726f6f74402f7812157463703a2f2f3132372e302e302e313a3337353431"
    "1a2463653730366266322d343131352d346234632d393939322d30363761346237636537363522243064"
    "6335653333642d666131332d343737372d386163612d6261336634623964653966642802322c0a06756e"
    "7573656412176967"
    "6e6974696f6e2e6d7367732e537472696e674d736720ffffffffffffffffff01"
)


def advertise_record() -> PublisherRecord:
    return PublisherRecord(
        "@/vm:root@/x", "tcp://127.0.0.1:37541", PUBLISHER, PUB_NODE, Scope.ALL,
        MessagePublisher("ignition.msgs.StringMsg"),
    )  # fmt: skip


def test_heartbeat_golden_bytes() -> None:
    message = DiscoveryMessage(DiscoveryType.HEARTBEAT, SUBSCRIBER)
    assert encode_discovery(message) == HEARTBEAT
    assert decode_discovery(HEARTBEAT) == message


def test_subscribe_golden_bytes() -> None:
    message = DiscoveryMessage(DiscoveryType.SUBSCRIBE, SUBSCRIBER, topic="@/vm:root@/x")
    assert encode_discovery(message) == SUBSCRIBE
    assert decode_discovery(SUBSCRIBE) == message


def test_advertise_golden_bytes() -> None:
    message = DiscoveryMessage(DiscoveryType.ADVERTISE, PUBLISHER, pub=advertise_record())
    assert encode_discovery(message) == ADVERTISE
    decoded = decode_discovery(ADVERTISE)
    assert decoded == message
    assert decoded.pub is not None
    assert decoded.pub.msg == MessagePublisher(
        "ignition.msgs.StringMsg", "unused", False, UNTHROTTLED
    )


def test_new_connection_layout() -> None:
    """Frame 6 of the dump, rebuilt field by field: 238 bytes, prefix 0x00ec."""
    record = PublisherRecord(
        "@/vm:root@/x", "tcp://127.0.0.1:37541", SUBSCRIBER, SUB_NODE, Scope.ALL,
        MessagePublisher("ignition.msgs.StringMsg", ctrl=PUBLISHER),
    )  # fmt: skip
    data = encode_discovery(DiscoveryMessage(DiscoveryType.NEW_CONNECTION, SUBSCRIBER, pub=record))
    assert len(data) == 238
    assert data[:2] == b"\xec\x00"
    assert data[42:47] == b"\x20\x06\x3a\xbf\x01"
    assert b"\x32\x4a\x0a\x24" + PUBLISHER.encode() + b"\x12\x17ignition.msgs.StringMsg" in data


def test_service_record_round_trip() -> None:
    record = PublisherRecord(
        "@/p@/srv", "tcp://127.0.0.1:1", PUBLISHER, PUB_NODE, Scope.HOST,
        srv=ServicePublisher("sock-id", "gz.msgs.StringMsg", "gz.msgs.Empty"),
    )  # fmt: skip
    message = DiscoveryMessage(DiscoveryType.ADVERTISE, PUBLISHER, relay=True, pub=record)
    assert decode_discovery(encode_discovery(message)) == message


@pytest.mark.parametrize(
    "data",
    [
        b"",
        b"\x05",
        HEARTBEAT[:-1],
        HEARTBEAT + b"\x00",
        b"\x2c\x00" + HEARTBEAT[2:],
        b"\x02\x00\xff\xff",
    ],
)
def test_malformed_datagrams_raise_remote_errors(data: bytes) -> None:
    with pytest.raises(RemoteProtocolError):
        decode_discovery(data)


def test_unknown_discovery_type() -> None:
    data = HEARTBEAT[:-1] + b"\x0c"
    with pytest.raises(UnknownMessageTypeError):
        decode_discovery(data)


def test_data_frames_match_the_capture() -> None:
    frames = encode_data(
        "@/vm:root@/x", "tcp://127.0.0.1:33245", b"\x12\x02hi", "ignition.msgs.StringMsg"
    )
    assert frames == [
        b"@/vm:root@/x",
        b"tcp://127.0.0.1:33245",
        b"\x12\x02hi",
        b"ignition.msgs.StringMsg",
    ]
    decoded = decode_data([memoryview(f) for f in frames])
    assert (decoded.topic, decoded.sender, decoded.msg_type) == (
        "@/vm:root@/x", "tcp://127.0.0.1:33245", "ignition.msgs.StringMsg",
    )  # fmt: skip
    assert bytes(decoded.payload) == b"\x12\x02hi"
    with pytest.raises(RemoteProtocolError, match="3 frames"):
        decode_data(frames[:3])
    with pytest.raises(RemoteProtocolError, match="UTF-8"):
        decode_data([b"\xff", *frames[1:]])


def test_service_frames() -> None:
    request = ServiceRequest(
        "@/p@/s", "tcp://127.0.0.1:2", "rid", "node", "req", b"\x01", "gz.msgs.A", "gz.msgs.B"
    )
    frames = encode_request("provider", request)
    assert len(frames) == 9
    assert frames[0] == b"provider"
    # The provider's ROUTER replaces frame 0 with the requester's identity.
    assert decode_request([b"\x00abcd", *frames[1:]]) == request
    response = ServiceResponse("@/p@/s", "node", "req", b"\x02", ok=False)
    frames = encode_response("rid", response)
    assert frames[1:] == [b"@/p@/s", b"node", b"req", b"\x02", b"0"]
    assert decode_response([b"provider", *frames[1:]]) == response
    with pytest.raises(RemoteProtocolError, match="result"):
        decode_response([b"provider", *frames[1:5], b"2"])
    with pytest.raises(RemoteProtocolError, match="frames"):
        decode_request(frames)

"""Byte layouts of the ZeroMQ backend, pure functions (docs/protocol-zmq-discovery.md §2.3,
docs/protocol-zmq-data.md §2.8.2, §2.9).

* Discovery datagram: little-endian uint16 body length + protobuf ``Discovery`` (§2.3).
* Data message: 4 ZMQ frames [FQN, sender PUB endpoint, payload, type name] (§2.8.2).
* Service request: 8 frames after the routing frame; response: 5 after it (§2.9.2, §2.9.3).

Decoders raise :class:`RemoteProtocolError` for anything a peer should not have sent.
"""

from __future__ import annotations

import enum
import re
import struct
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

from google.protobuf.message import DecodeError

from ros_gz_bridge_py.errors import LocalProtocolError, RemoteProtocolError
from ros_gz_bridge_py.msgs import message_class
from ros_gz_bridge_py.transport.api import Scope

#: Discovery wire version of every line from ign-transport8 to gz-transport15
#: (docs/protocol-lines.md §3).
WIRE_VERSION = 10
#: Largest datagram gz-transport receives or sends (kMaxRcvStr, §2.3).
MAX_DATAGRAM = 65535
#: ``msgs_per_sec`` of an unthrottled publisher (kUnthrottled, §2.3.1).
UNTHROTTLED = 0xFFFFFFFFFFFFFFFF
#: ``ctrl`` of an advertised message publisher (a vestige, §2.1).
UNUSED_CTRL = "unused"
#: Result frame of a service response (§2.9.3).
RESULT_OK = b"1"
RESULT_FAILED = b"0"

_LENGTH = struct.Struct("<H")
#: A publisher address we connect to: ``tcp://`` with a host name, IPv4 or [IPv6], and a port.
_TCP_ENDPOINT = re.compile(r"tcp://(?:[A-Za-z0-9.-]+|\[[0-9A-Fa-f:.]+\]):([0-9]{1,5})")
_MAX_PORT = 65535


def is_tcp_endpoint(address: str) -> bool:
    """True for ``tcp://host:port`` (port 1-65535), the only addresses gz advertises and the
    only ones we connect to when the network names them (docs/protocol-zmq-discovery.md §2.3.1):
    never ``ipc://``, ``inproc://`` or an interface-qualified form."""
    match = _TCP_ENDPOINT.fullmatch(address)
    return match is not None and 0 < int(match[1]) <= _MAX_PORT


class UnknownMessageTypeError(RemoteProtocolError):
    """A well-formed discovery datagram of a ``Discovery.Type`` this peer does not know."""


class DiscoveryType(enum.IntEnum):
    """``Discovery.Type`` (§2.3.1)."""

    UNINITIALIZED = 0
    ADVERTISE = 1
    SUBSCRIBE = 2
    UNADVERTISE = 3
    HEARTBEAT = 4
    BYE = 5
    NEW_CONNECTION = 6
    END_CONNECTION = 7
    SUBSCRIBERS_REQ = 8
    SUBSCRIBERS_REP = 9


@dataclass(frozen=True, slots=True)
class MessagePublisher:
    """``Discovery.Publisher.MessagePublisher``."""

    msg_type: str
    ctrl: str = UNUSED_CTRL
    throttled: bool = False
    msgs_per_sec: int = UNTHROTTLED


@dataclass(frozen=True, slots=True)
class ServicePublisher:
    """``Discovery.Publisher.ServicePublisher``."""

    socket_id: str
    request_type: str
    response_type: str


@dataclass(frozen=True, slots=True)
class PublisherRecord:
    """``Discovery.Publisher``: one advertised topic or service of one node."""

    topic: str
    address: str
    process_uuid: str
    node_uuid: str
    scope: Scope = Scope.ALL
    msg: MessagePublisher | None = None
    srv: ServicePublisher | None = None

    @property
    def msg_type(self) -> str:
        """The message type of a topic record ('' for a service record)."""
        return self.msg.msg_type if self.msg is not None else ""


@dataclass(frozen=True, slots=True)
class DiscoveryMessage:
    """One discovery datagram, decoded."""

    type: DiscoveryType
    process_uuid: str
    version: int = WIRE_VERSION
    relay: bool = False
    no_relay: bool = False
    #: ``sub.topic`` (SUBSCRIBE).
    topic: str | None = None
    pub: PublisherRecord | None = field(default=None)


def _discovery_class() -> type[Any]:
    return message_class("gz.msgs.Discovery")


def encode_discovery(message: DiscoveryMessage) -> bytes:
    """The datagram for ``message``: length prefix + protobuf body.

    Raises:
        LocalProtocolError: the body is longer than a datagram can carry.
    """
    proto = _discovery_class()()
    proto.version = message.version
    proto.process_uuid = message.process_uuid
    proto.type = int(message.type)
    if message.relay or message.no_relay:
        proto.flags.relay = message.relay
        proto.flags.no_relay = message.no_relay
    if message.topic is not None:
        proto.sub.topic = message.topic
    elif message.pub is not None:
        _fill_publisher(proto.pub, message.pub)
    body: bytes = proto.SerializeToString()
    if len(body) + _LENGTH.size > MAX_DATAGRAM:
        msg = (
            f"discovery message of {len(body)} bytes does not fit a datagram "
            f"(limit {MAX_DATAGRAM - _LENGTH.size}); use shorter topic names"
        )
        raise LocalProtocolError(msg)
    return _LENGTH.pack(len(body)) + body


def _fill_publisher(proto: Any, record: PublisherRecord) -> None:
    proto.topic = record.topic
    proto.address = record.address
    proto.process_uuid = record.process_uuid
    proto.node_uuid = record.node_uuid
    proto.scope = int(record.scope)
    if record.msg is not None:
        proto.msg_pub.ctrl = record.msg.ctrl
        proto.msg_pub.msg_type = record.msg.msg_type
        proto.msg_pub.throttled = record.msg.throttled
        proto.msg_pub.msgs_per_sec = record.msg.msgs_per_sec
    elif record.srv is not None:
        proto.srv_pub.socket_id = record.srv.socket_id
        proto.srv_pub.request_type = record.srv.request_type
        proto.srv_pub.response_type = record.srv.response_type


def decode_discovery(data: bytes) -> DiscoveryMessage:
    """Parse one datagram.

    The version is returned as received; the caller drops foreign versions.

    Raises:
        RemoteProtocolError: bad length prefix, unparsable body or unknown message type.
    """
    if len(data) < _LENGTH.size:
        msg = f"discovery datagram of {len(data)} bytes has no length prefix"
        raise RemoteProtocolError(msg)
    (length,) = _LENGTH.unpack_from(data)
    if length + _LENGTH.size != len(data):
        msg = f"discovery length prefix says {length} bytes but {len(data) - 2} follow"
        raise RemoteProtocolError(msg)
    proto = _discovery_class()()
    try:
        proto.ParseFromString(data[_LENGTH.size :])
    except DecodeError as error:
        msg = f"discovery body is not a Discovery message: {error}"
        raise RemoteProtocolError(msg) from error
    try:
        kind = DiscoveryType(proto.type)
    except ValueError as error:
        msg = f"unknown discovery message type {proto.type}"
        raise UnknownMessageTypeError(msg) from error
    contents = proto.WhichOneof("disc_contents")
    return DiscoveryMessage(
        type=kind,
        process_uuid=proto.process_uuid,
        version=proto.version,
        relay=proto.flags.relay,
        no_relay=proto.flags.no_relay,
        topic=proto.sub.topic if contents == "sub" else None,
        pub=_read_publisher(proto.pub) if contents == "pub" else None,
    )


def _read_publisher(proto: Any) -> PublisherRecord:
    try:
        scope = Scope(proto.scope)
    except ValueError as error:
        msg = f"unknown publisher scope {proto.scope}"
        raise RemoteProtocolError(msg) from error
    kind = proto.WhichOneof("pub_type")
    msg_pub: MessagePublisher | None = None
    srv_pub: ServicePublisher | None = None
    if kind == "msg_pub":
        m = proto.msg_pub
        msg_pub = MessagePublisher(m.msg_type, m.ctrl, m.throttled, m.msgs_per_sec)
    elif kind == "srv_pub":
        s = proto.srv_pub
        srv_pub = ServicePublisher(s.socket_id, s.request_type, s.response_type)
    return PublisherRecord(
        proto.topic, proto.address, proto.process_uuid, proto.node_uuid, scope, msg_pub, srv_pub
    )


# --- data plane ---------------------------------------------------------------------------

#: A ZMQ frame as pyzmq hands it over: bytes, or a zero-copy buffer.
Frame = bytes | bytearray | memoryview

DATA_FRAMES = 4


@dataclass(frozen=True, slots=True)
class DataMessage:
    """A received data message (§2.8.2). ``payload`` is not copied."""

    topic: str
    sender: str
    payload: Frame
    msg_type: str


def encode_data(topic: str, sender: str, payload: Frame, msg_type: str) -> list[Frame]:
    """The 4 frames a PUB socket sends for one message."""
    return [topic.encode(), sender.encode(), payload, msg_type.encode()]


def _text(frame: Frame, what: str) -> str:
    try:
        return bytes(frame).decode()
    except UnicodeDecodeError as error:
        msg = f"{what} frame is not UTF-8"
        raise RemoteProtocolError(msg) from error


def decode_data(frames: Sequence[Frame]) -> DataMessage:
    """Read the 4 frames of a data message.

    Raises:
        RemoteProtocolError: wrong frame count or non-text name frames.
    """
    if len(frames) != DATA_FRAMES:
        msg = f"data message has {len(frames)} frames, expected 4"
        raise RemoteProtocolError(msg)
    return DataMessage(
        _text(frames[0], "topic"), _text(frames[1], "sender"), frames[2], _text(frames[3], "type")
    )


# --- services ------------------------------------------------------------------------------

REQUEST_FRAMES = 9
RESPONSE_FRAMES = 6


@dataclass(frozen=True, slots=True)
class ServiceRequest:
    """A service request without its routing frame (§2.9.2)."""

    service: str
    response_address: str
    response_id: str
    node_uuid: str
    request_uuid: str
    payload: Frame
    request_type: str
    response_type: str


@dataclass(frozen=True, slots=True)
class ServiceResponse:
    """A service response without its routing frame (§2.9.3)."""

    service: str
    node_uuid: str
    request_uuid: str
    payload: Frame
    ok: bool


def encode_request(provider_id: str, request: ServiceRequest) -> list[Frame]:
    """The 9 frames a requester ROUTER sends to the provider with routing id ``provider_id``."""
    return [
        provider_id.encode(),
        request.service.encode(),
        request.response_address.encode(),
        request.response_id.encode(),
        request.node_uuid.encode(),
        request.request_uuid.encode(),
        request.payload,
        request.request_type.encode(),
        request.response_type.encode(),
    ]


def decode_request(frames: Sequence[Frame]) -> ServiceRequest:
    """Read a request as the replier ROUTER receives it (frame 0 = the sender's identity).

    Raises:
        RemoteProtocolError: wrong frame count or non-text name frames.
    """
    if len(frames) != REQUEST_FRAMES:
        msg = f"service request has {len(frames)} frames, expected 9"
        raise RemoteProtocolError(msg)
    service, address, response_id, node_uuid, request_uuid, request_type, response_type = (
        _text(frames[i], "request") for i in (1, 2, 3, 4, 5, 7, 8)
    )
    return ServiceRequest(
        service, address, response_id, node_uuid, request_uuid, frames[6], request_type,
        response_type,
    )  # fmt: skip


def encode_response(response_id: str, response: ServiceResponse) -> list[Frame]:
    """The 6 frames a replier ROUTER sends to the client's responseReceiver ``response_id``."""
    return [
        response_id.encode(),
        response.service.encode(),
        response.node_uuid.encode(),
        response.request_uuid.encode(),
        response.payload,
        RESULT_OK if response.ok else RESULT_FAILED,
    ]


def decode_response(frames: Sequence[Frame]) -> ServiceResponse:
    """Read a response as the responseReceiver ROUTER receives it (frame 0 = provider id).

    Raises:
        RemoteProtocolError: wrong frame count, non-text names or a result other than 1/0.
    """
    if len(frames) != RESPONSE_FRAMES:
        msg = f"service response has {len(frames)} frames, expected 6"
        raise RemoteProtocolError(msg)
    result = bytes(frames[5])
    if result not in (RESULT_OK, RESULT_FAILED):
        msg = f"service response result {result!r} is not '1' or '0'"
        raise RemoteProtocolError(msg)
    return ServiceResponse(
        _text(frames[1], "response"),
        _text(frames[2], "response"),
        _text(frames[3], "response"),
        frames[4],
        result == RESULT_OK,
    )

"""Discovery's repeated datagrams: ours encoded once, those heard decoded once
(docs/protocol-zmq-discovery.md §2.5).

Every process sends a HEARTBEAT and re-ADVERTISEs each of its records every second, so a
process hears the same bytes again and again, and sends the same bytes again and again: a
50-robot fleet's bridge at rest sent and heard about 300 a second, each a Python encode (4.6 µs)
or decode (12 µs). What is done with a datagram is unchanged; only the work of making or reading
its bytes is saved.
"""

from __future__ import annotations

from ros_gz_bridge_py.transport.zmq.wire import (
    DiscoveryMessage,
    DiscoveryType,
    PublisherRecord,
    decode_discovery,
    encode_discovery,
)

#: Distinct datagrams of at most DECODED_SIZE bytes remembered decoded (a peer's records and
#: heartbeats repeat each second; a few hundred bytes each): at most about 4 MB held.
DECODED_KEPT, DECODED_SIZE = 2048, 1024
#: The kinds sent again every second, unchanged.
REPEATED = frozenset({DiscoveryType.HEARTBEAT, DiscoveryType.ADVERTISE})


class DatagramMemo:
    """The encodings of our repeated datagrams and the decodings of the datagrams heard."""

    def __init__(self) -> None:
        self._encoded: dict[tuple[DiscoveryType, PublisherRecord | None], bytes] = {}
        self._decoded: dict[bytes, DiscoveryMessage] = {}

    def encode(self, message: DiscoveryMessage) -> bytes:
        """``message``'s bytes; a HEARTBEAT's or a record's ADVERTISE made once."""
        if message.type not in REPEATED:
            return encode_discovery(message)
        key = (message.type, message.pub)
        data = self._encoded.get(key)
        if data is None:
            data = self._encoded[key] = encode_discovery(message)
        return data

    def forget(self, record: PublisherRecord) -> None:
        """A record withdrawn: advertised anew, it is encoded as it then is."""
        self._encoded.pop((DiscoveryType.ADVERTISE, record), None)

    def decode(self, data: bytes) -> DiscoveryMessage:
        """``data`` decoded (raises as :func:`decode_discovery`), kept for its next repeat; a
        flood of distinct datagrams empties the memo, never grows it past DECODED_KEPT."""
        message = self._decoded.get(data)
        if message is not None:
            return message
        message = decode_discovery(data)
        if len(data) <= DECODED_SIZE:
            if len(self._decoded) >= DECODED_KEPT:
                self._decoded.clear()
            self._decoded[data] = message
        return message

    def decoded(self) -> list[bytes]:
        """The datagrams remembered decoded."""
        return list(self._decoded)

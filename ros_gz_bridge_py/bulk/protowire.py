"""Protobuf wire format, just enough to lift one bytes field out of a message (sans-IO).

A serialized protobuf message is a sequence of (tag, value) records; a record may appear in any
order and, for a singular field, the last occurrence wins. Splitting a message into "every other
record" plus "the bulk field" therefore keeps the meaning of both halves, and appending a record
to a serialized message sets that field.
"""

from __future__ import annotations

from ros_gz_bridge_py.errors import UndecodableError

_VARINT, _I64, _LEN, _I32 = 0, 1, 2, 5
_MAX_VARINT_BYTES = 10


def read_varint(buf: memoryview, pos: int) -> tuple[int, int]:
    """Decode the varint at ``pos``; return (value, position after it)."""
    value = 0
    for shift in range(0, 7 * _MAX_VARINT_BYTES, 7):
        if pos >= len(buf):
            msg = "protobuf payload ends inside a varint"
            raise UndecodableError(msg)
        byte = buf[pos]
        pos += 1
        value |= (byte & 0x7F) << shift
        if byte < 0x80:
            return value, pos
    msg = "protobuf payload has a varint longer than 10 bytes"
    raise UndecodableError(msg)


def encode_varint(value: int) -> bytes:
    out = bytearray()
    while value >= 0x80:
        out.append((value & 0x7F) | 0x80)
        value >>= 7
    out.append(value)
    return bytes(out)


def bytes_field_prefix(field_number: int, length: int) -> bytes:
    """The tag and length that precede ``length`` bytes of field ``field_number``."""
    return encode_varint(field_number << 3 | _LEN) + encode_varint(length)


def split_bytes_field(payload: memoryview, field_number: int) -> tuple[bytes, int, int]:
    """Split ``payload`` into (every other record, where the value of bytes field
    ``field_number`` starts, its length); the value is not copied (0, 0 when it is absent).

    Raises:
        ConversionError: the payload is not a well-formed protobuf message.
    """
    rest: list[memoryview] = []
    bulk_at = bulk_length = 0
    start = pos = 0
    end = len(payload)
    while pos < end:
        record = pos
        tag, pos = read_varint(payload, pos)
        wire_type = tag & 7
        if wire_type == _VARINT:
            _, pos = read_varint(payload, pos)
        elif wire_type == _I64:
            pos += 8
        elif wire_type == _I32:
            pos += 4
        elif wire_type == _LEN:
            length, pos = read_varint(payload, pos)
            if tag >> 3 == field_number:
                if pos + length > end:
                    break
                rest.append(payload[start:record])
                bulk_at, bulk_length = pos, length
                pos += length
                start = pos
                continue
            pos += length
        else:
            msg = f"protobuf payload has unsupported wire type {wire_type} at byte {record}"
            raise UndecodableError(msg)
    if pos != end:
        msg = f"protobuf payload of {end} bytes is truncated (a record runs past its end)"
        raise UndecodableError(msg)
    rest.append(payload[start:end])
    return b"".join(rest), bulk_at, bulk_length

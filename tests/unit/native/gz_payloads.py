"""Gazebo payloads for the native transcoder's tests: random messages, valid encodings other
than the canonical one, and malformed variants of a valid payload.

The protobuf runtime writes one canonical form (fields by number, repeated numbers packed, no
duplicates); a Gazebo peer or a hand-built payload may send any valid form, so
:func:`encode` writes a message in a random valid one: fields in any order, a singular value
preceded by a decoy (the last one wins), repeated numbers packed, unpacked or in several runs,
varints longer than needed, unknown fields of every wire type that parses.
"""

from __future__ import annotations

import math
import random
import struct
from collections.abc import Callable, Iterator
from typing import Any

_DOUBLE, _FLOAT, _INT64, _UINT64, _INT32, _FIXED64, _FIXED32, _BOOL = 1, 2, 3, 4, 5, 6, 7, 8
_STRING, _MESSAGE, _BYTES, _UINT32, _ENUM, _SFIXED32, _SFIXED64 = 9, 11, 12, 13, 14, 15, 16
_SINT32, _SINT64 = 17, 18
VARINT, I64, LEN, SGROUP, EGROUP, I32 = 0, 1, 2, 3, 4, 5
_HEADER_TYPES = {"gz.msgs.Header", "ignition.msgs.Header"}
_MASK64 = 2**64 - 1
_FIXED = {_DOUBLE: "<d", _FIXED64: "<Q", _SFIXED64: "<q", _FLOAT: "<f", _FIXED32: "<I"}
_FIXED[_SFIXED32] = "<i"
_INT_RANGES = {
    _INT32: (-(2**31), 2**31 - 1),
    _SINT32: (-(2**31), 2**31 - 1),
    _SFIXED32: (-(2**31), 2**31 - 1),
    _ENUM: (-(2**31), 2**31 - 1),
    _UINT32: (0, 2**32 - 1),
    _FIXED32: (0, 2**32 - 1),
    _INT64: (-(2**63), 2**63 - 1),
    _SINT64: (-(2**63), 2**63 - 1),
    _SFIXED64: (-(2**63), 2**63 - 1),
    _UINT64: (0, 2**64 - 1),
    _FIXED64: (0, 2**64 - 1),
}
_DOUBLES = [
    0.0, -0.0, math.nan, -math.nan, math.inf, -math.inf, 5e-324, -2.2250738585072014e-308,
    1.7976931348623157e308, 3.4028234663852886e38, -3.4028235677973366e38, 3.5e38, 1e-46,
    struct.unpack("<d", bytes.fromhex("0100000000f07f7f"))[0],  # a NaN with a payload
]  # fmt: skip
_FLOATS = [0.0, -0.0, math.nan, math.inf, -math.inf, 3.4028234663852886e38, 1e-45, -1.5]
_TEXTS = [
    "", "frame_id", "child_frame_id", "a::b::c", ":::", "::", "x:y", "é漢字🙂::z", "\u07ff\uffff",
    "w::" * 40, "\U0010ffff",
]  # fmt: skip
_KEYS = ["frame_id", "child_frame_id", "other", "", "frame_id "]


def wire_of(field: Any) -> int:
    """The wire type of one element of ``field``."""
    if field.type in (_STRING, _BYTES, _MESSAGE):
        return LEN
    if field.type in (_DOUBLE, _FIXED64, _SFIXED64):
        return I64
    if field.type in (_FLOAT, _FIXED32, _SFIXED32):
        return I32
    return VARINT


def varint(value: int, extra: int = 0) -> bytes:
    """``value`` (two's complement in 64 bits) as a varint, ``extra`` bytes longer than needed
    (a valid encoding while it stays within 10 bytes)."""
    value &= _MASK64
    out = bytearray()
    while True:
        byte, value = value & 0x7F, value >> 7
        if not value:
            break
        out.append(byte | 0x80)
    out += bytes([byte | 0x80] if extra else [byte])
    for k in range(extra):
        out += b"\x80" if k < extra - 1 else b"\x00"
    return bytes(out)


def tag(number: int, wire: int) -> bytes:
    return varint(number << 3 | wire)


def length_delimited(number: int, data: bytes, extra: int = 0) -> bytes:
    return tag(number, LEN) + varint(len(data), extra) + data


# ---- random messages -------------------------------------------------------------------------


def _random_text(rng: random.Random) -> str:
    if rng.random() < 0.7:
        return rng.choice(_TEXTS)
    points = [rng.choice([rng.randrange(1, 0x80), rng.randrange(0xE000, 0x110000)])]
    points += [rng.randrange(1, 0xD800) for _ in range(rng.randrange(0, 12))]
    return "".join(map(chr, points))


def random_scalar(field: Any, rng: random.Random) -> Any:
    """A value of ``field``'s type, often an extreme one (never a string with a NUL)."""
    kind = field.type
    if kind == _DOUBLE:
        special = rng.random() < 0.5
        return rng.choice(_DOUBLES) if special else struct.unpack("<d", rng.randbytes(8))[0]
    if kind == _FLOAT:
        special = rng.random() < 0.5
        return rng.choice(_FLOATS) if special else struct.unpack("<f", rng.randbytes(4))[0]
    if kind == _BOOL:
        return rng.random() < 0.5
    if kind == _STRING:
        return _random_text(rng)
    if kind == _BYTES:
        return rng.randbytes(rng.randrange(0, 6))
    low, high = _INT_RANGES[kind]
    if rng.random() < 0.5:
        return rng.choice([low, high, 0, 1, -1 if low else 2, high // 2 + 1, 2**31, 2**32 - 1])
    return rng.randint(low, high)


def _clip(field: Any, value: Any) -> Any:
    """``value`` where the field's type can hold it (the extreme lists are shared)."""
    if field.type in _INT_RANGES:
        low, high = _INT_RANGES[field.type]
        return value if low <= value <= high else high
    return value


def _random_header(header: Any, rng: random.Random, depth: int) -> None:
    if rng.random() < 0.8:
        random_fill(header.stamp, rng, depth + 1)
    for _ in range(rng.randrange(0, 5)):
        entry = header.data.add()
        if rng.random() < 0.9:
            entry.key = rng.choice(_KEYS)
        entry.value.extend(_random_text(rng) for _ in range(rng.randrange(0, 3)))


def random_fill(msg: Any, rng: random.Random, depth: int = 0) -> Any:
    """Sets a random choice of ``msg``'s fields to random values (nested messages too, up to a
    depth) and returns it."""
    if msg.DESCRIPTOR.full_name in _HEADER_TYPES:
        _random_header(msg, rng, depth)
        return msg
    for field in msg.DESCRIPTOR.fields:
        if rng.random() < 0.25:
            continue
        count = rng.randrange(0, 5 if depth < 2 else 3) if field.is_repeated else 1
        if field.message_type is not None:
            if depth >= 5:
                continue
            for _ in range(count):
                sub = (
                    getattr(msg, field.name).add()
                    if field.is_repeated
                    else getattr(msg, field.name)
                )
                sub.SetInParent()
                random_fill(sub, rng, depth + 1)
        elif field.is_repeated:
            getattr(msg, field.name).extend(
                _clip(field, random_scalar(field, rng)) for _ in range(count)
            )
        else:
            setattr(msg, field.name, _clip(field, random_scalar(field, rng)))
    return msg


# ---- valid encodings -------------------------------------------------------------------------


def _scalar_bytes(field: Any, value: Any, extra: int) -> bytes:
    if field.type in _FIXED:
        return struct.pack(_FIXED[field.type], value)
    if field.type == _SINT32:
        return varint((value << 1) ^ (value >> 31), extra)
    if field.type == _SINT64:
        return varint((value << 1) ^ (value >> 63), extra)
    return varint(int(value), extra)


def _extra(rng: random.Random, encoded: int, limit: int = 10) -> int:
    """Extra varint bytes: usually none, sometimes up to the limit (10 bytes for a value, 5
    for a length: the protobuf runtime refuses a longer length)."""
    return rng.randrange(0, limit + 1 - encoded) if rng.random() < 0.2 else 0


def _length(data: bytes, rng: random.Random) -> bytes:
    """The length prefix of ``data``, sometimes longer than needed."""
    return varint(len(data), _extra(rng, len(varint(len(data))), limit=5))


def _element(field: Any, value: Any, rng: random.Random) -> bytes:
    """One element of ``field`` without its tag."""
    if field.type == _MESSAGE:
        data = encode(value, rng)
        return _length(data, rng) + data
    if field.type in (_STRING, _BYTES):
        text: bytes = value.encode() if field.type == _STRING else bytes(value)
        return _length(text, rng) + text
    plain = _scalar_bytes(field, value, 0)
    return _scalar_bytes(field, value, _extra(rng, len(plain)) if wire_of(field) == 0 else 0)


def _packed(field: Any, values: list[Any], rng: random.Random) -> bytes:
    """Repeated numbers in runs: packed, unpacked or mixed (all are valid)."""
    out = b""
    rest = list(values)
    while rest:
        take = rng.randrange(1, len(rest) + 1)
        run, rest = rest[:take], rest[take:]
        if rng.random() < 0.5:
            body = b"".join(_element(field, value, rng) for value in run)
            out += length_delimited(field.number, body)
        else:
            out += b"".join(
                tag(field.number, wire_of(field)) + _element(field, v, rng) for v in run
            )
    return out


def _decoy(field: Any, rng: random.Random) -> bytes:
    """An earlier occurrence of a singular number or string, which the last one overrides."""
    if field.type == _MESSAGE or rng.random() < 0.8:
        return b""
    return tag(field.number, wire_of(field)) + _element(field, random_scalar(field, rng), rng)


def _unknown(numbers: set[int], rng: random.Random) -> bytes:
    number = rng.choice([n for n in (7, 19, 99, 1000, 2**29 - 1) if n not in numbers] or [2**28])
    wire = rng.choice([VARINT, I64, LEN, I32])
    if wire == VARINT:
        return tag(number, wire) + varint(rng.randrange(2**64))
    if wire == LEN:
        return length_delimited(number, rng.randbytes(rng.randrange(0, 9)))
    return tag(number, wire) + rng.randbytes(8 if wire == I64 else 4)


def encode(msg: Any, rng: random.Random) -> bytes:
    """``msg`` in a random valid wire form (parsing it gives ``msg``, plus unknown fields)."""
    parts = []
    for field, value in msg.ListFields():
        if field.is_repeated and wire_of(field) != LEN:
            parts.append(_packed(field, list(value), rng))
        elif field.is_repeated:
            parts.append(b"".join(tag(field.number, LEN) + _element(field, v, rng) for v in value))
        else:
            parts.append(_decoy(field, rng) + tag(field.number, wire_of(field)))
            parts[-1] += _element(field, value, rng)
    if rng.random() < 0.2:
        parts.append(_unknown({f.number for f in msg.DESCRIPTOR.fields}, rng))
    rng.shuffle(parts)
    return b"".join(parts)


# ---- malformed variants ----------------------------------------------------------------------


def top_fields(payload: bytes) -> Iterator[tuple[int, int, int, int]]:
    """(start, number, wire, end of the tag and any length) of each top-level field of a valid
    canonical payload, whose value runs to the next start."""
    pos = 0
    while pos < len(payload):
        start = pos
        key, pos = _read_varint(payload, pos)
        number, wire = key >> 3, key & 7
        head = pos
        if wire == VARINT:
            _value, pos = _read_varint(payload, pos)
        elif wire == LEN:
            length, pos = _read_varint(payload, pos)
            head = pos
            pos += length
        else:
            pos += 8 if wire == I64 else 4
        yield start, number, wire, head


def _read_varint(data: bytes, pos: int) -> tuple[int, int]:
    value, shift = 0, 0
    while True:
        byte = data[pos]
        value |= (byte & 0x7F) << shift
        pos, shift = pos + 1, shift + 7
        if not byte & 0x80:
            return value, pos


def truncations(payload: bytes) -> Iterator[bytes]:
    return (payload[:k] for k in range(len(payload)))


def bit_flips(payload: bytes, rng: random.Random, most: int) -> Iterator[bytes]:
    """Single-bit flips: all of them, or ``most`` of them at random positions."""
    bits = range(len(payload) * 8)
    chosen = bits if len(bits) <= most else rng.sample(bits, most)
    for bit in chosen:
        flipped = bytearray(payload)
        flipped[bit // 8] ^= 1 << (bit % 8)
        yield bytes(flipped)


def bad_utf8(payload: bytes, marker: bytes) -> Iterator[bytes]:
    """For each occurrence of the 2-byte ``marker`` (a character in one string field), the
    payload with it replaced by ill-formed UTF-8 of the same length (a lone lead byte, an
    overlong ``/``), so that the framing stays valid."""
    at = payload.find(marker)
    while at >= 0:
        for bad in (b"\xc3\x28", b"\xc0\xaf", b"\xff\xfe"):
            yield payload[:at] + bad + payload[at + 2 :]
        at = payload.find(marker, at + 1)


def oversized_lengths(payload: bytes) -> Iterator[bytes]:
    """Each top-level length-delimited field with a length past the end of the payload."""
    for start, number, wire, head in top_fields(payload):
        if wire != LEN:
            continue
        length, _ = _read_varint(payload, len(tag(number, LEN)) + start)
        rest = payload[head:]
        for wrong in (len(rest) + 1, length + 2**31, 2**32 + length, 2**63, _MASK64):
            yield payload[:start] + tag(number, LEN) + varint(wrong) + rest


def long_lengths(payload: bytes, size: int) -> Iterator[bytes]:
    """Each top-level length-delimited field with its length written in ``size`` bytes (the
    same value: valid up to 5 bytes, refused by the runtime above)."""
    for start, number, wire, head in top_fields(payload):
        if wire != LEN:
            continue
        length, at = _read_varint(payload, len(tag(number, LEN)) + start)
        minimal = at - len(tag(number, LEN)) - start
        if minimal <= size:
            prefix = tag(number, LEN) + varint(length, size - minimal)
            yield payload[:start] + prefix + payload[head:]


def wrong_wire_types(payload: bytes) -> Iterator[bytes]:
    """Each top-level field re-sent with each other wire type that frames a value."""
    bodies: dict[int, Callable[[], bytes]] = {
        VARINT: lambda: varint(5),
        I64: lambda: bytes(8),
        LEN: lambda: varint(3) + b"\x08\x01\x00",
        I32: lambda: bytes(4),
    }
    for _start, number, wire, _head in top_fields(payload):
        for other, body in bodies.items():
            if other != wire:
                yield payload + tag(number, other) + body()


def odd_tags() -> list[bytes]:
    """Tags and varints the protobuf runtime refuses or handles apart: field 0, wire types 6
    and 7, a group, an 11-byte varint, a tag longer than 5 bytes."""
    return [
        b"\x00\x01",
        b"\x0e\x00",
        b"\x0f\x00",
        tag(9, SGROUP) + tag(9, EGROUP),
        tag(9, SGROUP),
        tag(9, EGROUP),
        tag(9, VARINT) + b"\xff" * 10 + b"\x01",
        tag(9, VARINT) + b"\xff" * 9 + b"\x7f",
        b"\x88\x80\x80\x80\x80\x00\x01",
        b"\xf8\xff\xff\xff\x7f\x01",
    ]

"""Lifting one bytes field out of a protobuf payload, against the real protobuf runtime."""

from __future__ import annotations

import pytest

from ros_gz_bridge_py.bulk.protowire import (
    bytes_field_prefix,
    encode_varint,
    read_varint,
    split_bytes_field,
)
from ros_gz_bridge_py.errors import ConversionError
from ros_gz_bridge_py.msgs import message_class

GzImage = message_class("gz.msgs.Image")
DATA = 5


def _image(data: bytes) -> object:
    image = GzImage(width=300, height=2, step=900, pixel_format_type=3, data=data)
    image.header.stamp.sec = -5
    image.header.stamp.nsec = 77
    entry = image.header.data.add()
    entry.key = "frame_id"
    entry.value.append("cam")
    return image


@pytest.mark.parametrize("value", [0, 1, 127, 128, 300, 2**32 - 1, 2**63 + 5])
def test_varint_round_trip(value: int) -> None:
    encoded = encode_varint(value)
    assert read_varint(memoryview(encoded + b"\xff"), 0) == (value, len(encoded))


def test_split_keeps_every_other_field_and_views_the_data() -> None:
    data = bytes(range(256)) * 3
    payload = _image(data).SerializeToString()  # type: ignore[attr-defined]
    rest, at, length = split_bytes_field(memoryview(payload), DATA)
    assert payload[at : at + length] == data
    assert payload.index(data) == at  # where the value is, not a copy of it
    expected = _image(b"")
    assert GzImage.FromString(rest) == expected
    assert GzImage.FromString(rest + bytes_field_prefix(DATA, len(data)) + data) == _image(data)


def test_field_anywhere_and_last_occurrence_wins() -> None:
    small = _image(b"").SerializeToString()  # type: ignore[attr-defined]
    first = bytes_field_prefix(DATA, 3) + b"old"
    last = bytes_field_prefix(DATA, 4) + b"new!"
    payload = first + small + last
    rest, at, length = split_bytes_field(memoryview(payload), DATA)
    assert payload[at : at + length] == b"new!"
    assert GzImage.FromString(payload).data == b"new!"
    assert GzImage.FromString(rest) == _image(b"")


def test_absent_field_is_empty() -> None:
    payload = _image(b"").SerializeToString()  # type: ignore[attr-defined]
    assert split_bytes_field(memoryview(payload), DATA) == (payload, 0, 0)


@pytest.mark.parametrize(
    ("payload", "reason"),
    [
        (bytes_field_prefix(DATA, 10) + b"short", "truncated"),
        (bytes_field_prefix(1, 10) + b"short", "truncated"),
        (b"\x08\xff\xff", "ends inside a varint"),
        (b"\x08" + b"\xff" * 11, "longer than 10 bytes"),
        (b"\x0b\x00", "wire type 3"),
        (b"\x11\x00\x00", "truncated"),
    ],
)
def test_malformed_payloads_are_conversion_errors(payload: bytes, reason: str) -> None:
    with pytest.raises(ConversionError, match=reason):
        split_bytes_field(memoryview(payload), DATA)

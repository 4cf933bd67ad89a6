"""What a pair needs for the bulk path, and the two conversions built on it."""

from __future__ import annotations

import struct
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from google.protobuf.message import DecodeError
from rclpy.serialization import deserialize_message, serialize_message

from ros_gz_bridge_py.bulk.cdr import Layout, locate_bulk
from ros_gz_bridge_py.bulk.protowire import bytes_field_prefix, split_bytes_field
from ros_gz_bridge_py.errors import ConversionError, UndecodableError

_EMPTY_SEQUENCE = b"\0\0\0\0"


@dataclass(frozen=True)
class Rows:
    """``count`` rows of ``size`` bytes, one every ``stride`` bytes from the bulk field's start.

    What an output takes of row-padded data (``stride`` > ``size``): the padding is left out.
    """

    count: int
    size: int
    stride: int


#: What an output takes of the bulk field: a prefix of that many bytes, or rows.
Take = int | Rows

#: Converts a message without its bulk field, given the bulk field's length; returns the other
#: side's message without its bulk field and what it takes of the bulk bytes.
#: Raises ConversionError when the metadata does not match the bulk field's length.
MetaConverter = Callable[[Any, int], tuple[Any, Take]]


def taken(bulk: memoryview, take: Take) -> tuple[list[memoryview], int]:
    """The views of ``bulk`` that ``take`` selects, and their total size (joining them is the
    one copy)."""
    if isinstance(take, int):
        end, size = take, take
    else:
        end, size = (take.count - 1) * take.stride + take.size, take.count * take.size
    if end > len(bulk):  # the meta converter checked the sizes: a bug if it happens
        msg = f"{take} takes bytes past the {len(bulk)} of the bulk field"
        raise ValueError(msg)
    if isinstance(take, int):
        return [bulk[:take]], size
    starts = range(0, take.count * take.stride, take.stride)
    return [bulk[start : start + take.size] for start in starts], size


@dataclass(frozen=True)
class BulkPath:
    """How one pair's bulk field maps between the gz protobuf and the ROS CDR.

    The ROS fields after the bulk field must all be 1-byte aligned (bool, uint8), so that
    splicing bytes in does not move their alignment; :func:`~.cdr.layout_until` checks it.
    """

    #: Field number of the bulk ``bytes`` field in the gz message.
    gz_field: int
    #: The ROS message's CDR layout up to and including its ``uint8[]`` bulk field
    #: (from :func:`~.cdr.layout_until`).
    ros_layout: Layout
    gz_meta_to_ros: MetaConverter
    ros_meta_to_gz: MetaConverter


def gz_to_ros_cdr(
    path: BulkPath,
    gz_class: type[Any],
    payload: memoryview,
    finish: Callable[[Any], None] | None = None,
) -> bytes | memoryview:
    """Gazebo payload -> serialized ROS message; the bulk bytes are copied at most once.

    ``finish`` may edit the ROS message (header overrides) before it is serialized. A writable
    ``payload`` is the caller's own (``transport/api.py`` ``Callback``): when the bytes around
    the bulk field have room for the CDR before and after it, they are written there and the
    result is a view of ``payload``, the bulk bytes not copied at all (:func:`in_place`).
    """
    rest, bulk_at, bulk_length = split_bytes_field(payload, path.gz_field)
    try:
        small = gz_class.FromString(rest)
    except DecodeError as err:
        msg = f"{gz_class.DESCRIPTOR.full_name} payload is not a valid message: {err}"
        raise UndecodableError(msg) from err
    ros, take = path.gz_meta_to_ros(small, bulk_length)
    if finish is not None:
        finish(ros)
    cdr = memoryview(serialize_message(ros))
    where = locate_bulk(cdr, path.ros_layout)
    if where is None:  # rclpy always writes plain CDR; kept total for the type checker
        msg = "rclpy produced a serialized message that is not plain CDR"
        raise ConversionError(msg)
    bulk = payload[bulk_at : bulk_at + bulk_length]
    pieces, size = taken(bulk, take)
    length = struct.pack("<I" if where.little_endian else ">I", size)
    head, tail = bytes(cdr[: where.length_at]) + length, cdr[where.end :]
    if isinstance(take, int):
        built = in_place(payload, head, (bulk_at, bulk_at + take), tail)
        if built is not None:
            return built
    return b"".join((head, *pieces, tail))


def in_place(
    payload: memoryview, head: bytes, bulk: tuple[int, int], tail: memoryview
) -> memoryview | None:
    """``head``, ``payload[bulk[0]:bulk[1]]`` and ``tail`` as one view of ``payload``, written
    over the records before and after the bulk bytes (already parsed), or None when
    ``payload`` is read-only or those records are shorter than ``head`` or ``tail``.

    A Gazebo camera's header (stamp, ``frame_id``, ``seq``), width, height and step take more
    bytes before its data than a sensor_msgs/Image's CDR does, so a camera frame's 6 MB are
    handed to the DDS write where ZeroMQ received them.
    """
    start, end = bulk[0] - len(head), bulk[1] + len(tail)
    if payload.readonly or start < 0 or end > len(payload):
        return None
    payload[start : bulk[0]] = head
    payload[bulk[1] : end] = tail
    return payload[start:end]


def ros_cdr_to_gz(path: BulkPath, ros_class: type[Any], cdr: bytes) -> bytes | None:
    """Serialized ROS message -> Gazebo payload; the bulk bytes are copied once.

    Returns None when ``cdr`` is not plain CDR (another encapsulation); the caller then
    deserializes it whole and takes the object path.
    """
    view = memoryview(cdr)
    where = locate_bulk(view, path.ros_layout)
    if where is None:
        return None
    ros = deserialize_message(
        b"".join((view[: where.length_at], _EMPTY_SEQUENCE, view[where.end :])), ros_class
    )
    gz, take = path.ros_meta_to_gz(ros, where.end - where.start)
    pieces, size = taken(view[where.start : where.end], take)
    prefix = bytes_field_prefix(path.gz_field, size)
    return b"".join((gz.SerializeToString(), prefix, *pieces))

"""Classic CDR (XCDR1), just enough to find one ``uint8[]`` field in a serialized ROS message.

A serialized ROS 2 message is a 4-byte encapsulation header (``00 01`` little endian, ``00 00``
big endian, then two option bytes) and the body, whose primitives are aligned to their size
counted from the start of the body. Strings and sequences are a ``uint32`` count then the
elements. A :data:`Layout` lists a message's fields up to and including the bulk field, in the
tokens below; :func:`locate_bulk` walks it (sans-IO, no copies).
"""

from __future__ import annotations

import struct
from dataclasses import dataclass
from typing import Union

from ros_gz_bridge_py.errors import ConversionError

#: Encapsulation identifiers of plain CDR: big endian, little endian.
CDR_BE = b"\x00\x00"
CDR_LE = b"\x00\x01"
HEADER_SIZE = 4

#: A field of a layout: "u8" (also bool, char), "u32" (also int32, float32), "str", "bulk"
#: (the uint8[] being looked for), or a sequence of structs given by their own layout.
Token = Union[str, "Sequence"]
Layout = tuple[Token, ...]


@dataclass(frozen=True)
class Sequence:
    """An unbounded sequence of structs with layout ``element``."""

    element: Layout


#: std_msgs/Header: builtin_interfaces/Time (int32 sec, uint32 nanosec), string frame_id.
HEADER: Layout = ("u32", "u32", "str")


@dataclass(frozen=True)
class BulkLocation:
    """Where the bulk field sits in a serialized message."""

    #: Offset of the field's uint32 length.
    length_at: int
    #: Offsets of its first byte and one past its last.
    start: int
    end: int
    little_endian: bool


def locate_bulk(buf: memoryview, layout: Layout) -> BulkLocation | None:
    """Walk ``layout`` over serialized message ``buf`` to its ``"bulk"`` token.

    Returns None when the encapsulation is not plain CDR (the caller falls back to rclpy).

    Raises:
        ConversionError: the message ends before the layout does.
    """
    if len(buf) < HEADER_SIZE or buf[:2] not in {CDR_LE, CDR_BE}:
        return None
    walker = _Walker(buf, little_endian=buf[:2] == CDR_LE)
    location = walker.walk(layout)
    if location is None:
        msg = f"layout {layout!r} has no 'bulk' field"
        raise ValueError(msg)
    return location


class _Walker:
    def __init__(self, buf: memoryview, *, little_endian: bool) -> None:
        self.buf = buf
        self.little_endian = little_endian
        self._u32 = struct.Struct("<I" if little_endian else ">I")
        self.pos = HEADER_SIZE

    def walk(self, layout: Layout) -> BulkLocation | None:
        for field in layout:
            if field == "u8":
                self._advance(1)
            elif field == "u32":
                self._count()
            elif field == "str":
                self._advance(self._count())
            elif field == "bulk":
                length_at = self.pos = self._aligned()
                size = self._count()
                start = self.pos
                self._advance(size)
                return BulkLocation(length_at, start, self.pos, self.little_endian)
            elif isinstance(field, Sequence):
                for _ in range(self._count()):
                    self.walk(field.element)
            else:
                msg = f"unknown CDR layout token {field!r}"
                raise ValueError(msg)
        return None

    def _aligned(self) -> int:
        return self.pos + (-(self.pos - HEADER_SIZE) % 4)

    def _count(self) -> int:
        self.pos = self._aligned()
        self._advance(4)
        value: int = self._u32.unpack_from(self.buf, self.pos - 4)[0]
        return value

    def _advance(self, size: int) -> None:
        self.pos += size
        if self.pos > len(self.buf):
            msg = f"serialized ROS message of {len(self.buf)} bytes ends inside a field"
            raise ConversionError(msg)

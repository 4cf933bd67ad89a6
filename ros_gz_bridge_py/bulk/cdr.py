"""Classic CDR (XCDR1), just enough to find one ``uint8[]`` field in a serialized ROS message.

A serialized ROS 2 message is a 4-byte encapsulation header (``00 01`` little endian, ``00 00``
big endian, then two option bytes) and the body, whose primitives are aligned to their size
counted from the start of the body. Strings and sequences are a ``uint32`` count then the
elements. A :data:`Layout` lists a message's fields up to and including the bulk field, in the
tokens below; :func:`layout_until` derives it from rclpy's type description and
:func:`locate_bulk` walks it (sans-IO, no copies).
"""

from __future__ import annotations

import struct
from dataclasses import dataclass
from typing import Any, Union

from ros_gz_bridge_py.errors import ConversionError
from ros_gz_bridge_py.ros import cdr_types

#: Encapsulation identifiers of plain CDR: big endian, little endian.
CDR_BE = b"\x00\x00"
CDR_LE = b"\x00\x01"
HEADER_SIZE = 4

#: A field of a layout: a primitive by its size, "u8", "u16", "u32" or "u64" (whatever its type),
#: "str", "bulk" (the uint8[] being looked for), or a sequence of structs given by their own
#: layout.
Token = Union[str, "Sequence"]
Layout = tuple[Token, ...]


@dataclass(frozen=True)
class Sequence:
    """An unbounded sequence of structs with layout ``element``."""

    element: Layout


#: Primitive tokens by wire size (and alignment).
_SIZE_TOKENS = {1: "u8", 2: "u16", 4: "u32", 8: "u64"}
_TOKEN_SIZES = {token: size for size, token in _SIZE_TOKENS.items()}
#: Element types of a bulk field: one byte each.
_BULK_ELEMENTS = frozenset({"uint8", "int8", "octet"})


def layout_until(msg_class: type[Any], field: str) -> Layout:
    """The layout of ``msg_class`` up to its ``uint8[]`` field ``field``, which ends it as "bulk".

    Raises:
        ValueError: ``field`` is not a sequence of one-byte elements (uint8, int8, byte), a
            field after it is wider than one byte (splicing bytes in would move its
            alignment), or a field before it has no token (a sequence of primitives).
    """
    fields = cdr_types.fields_of(msg_class)
    names = [name for name, _ in fields]
    if field not in names:
        msg = f"{msg_class.__name__} has no field {field!r}"
        raise ValueError(msg)
    index = names.index(field)
    bulk = fields[index][1]
    element = getattr(bulk, "value_type", None)
    if (
        type(bulk).__name__ not in cdr_types.SEQUENCE_TYPES
        or getattr(element, "typename", None) not in _BULK_ELEMENTS
    ):
        msg = f"{msg_class.__name__}.{field} is not a sequence of one-byte elements"
        raise ValueError(msg)
    for name, slot in fields[index + 1 :]:
        if cdr_types.basic_size(slot) != 1:
            msg = f"{msg_class.__name__}.{name} after {field} is not one byte wide"
            raise ValueError(msg)
    tokens: list[Token] = []
    for _, slot in fields[:index]:
        tokens.extend(_tokens(slot))
    return (*tokens, "bulk")


def _tokens(slot: Any) -> Layout:
    size = cdr_types.basic_size(slot)
    if size is not None:
        return (_SIZE_TOKENS[size],)
    kind = type(slot).__name__
    if kind in cdr_types.STRING_TYPES:
        return ("str",)
    if kind == "NamespacedType":
        return _struct_tokens(cdr_types.nested_class(slot))
    if kind in cdr_types.SEQUENCE_TYPES and type(slot.value_type).__name__ == "NamespacedType":
        return (Sequence(_struct_tokens(cdr_types.nested_class(slot.value_type))),)
    msg = f"no CDR layout token for a field of type {kind}"
    raise ValueError(msg)


def _struct_tokens(msg_class: type[Any]) -> Layout:
    fields = cdr_types.fields_of(msg_class)
    if not fields:  # an empty message still carries one uint8 on the wire
        return ("u8",)
    tokens: list[Token] = []
    for _, slot in fields:
        tokens.extend(_tokens(slot))
    return tuple(tokens)


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
    little_endian = plain_cdr_endianness(buf)
    if little_endian is None:
        return None
    walker = _Walker(buf, little_endian=little_endian)
    location = walker.walk(layout)
    if location is None:
        msg = f"layout {layout!r} has no 'bulk' field"
        raise ValueError(msg)
    return location


def plain_cdr_endianness(buf: memoryview) -> bool | None:
    """True for little-endian plain CDR, False for big-endian, None for anything else.

    Reads the two identifier bytes as integers: hashing a slice of a memoryview
    (``buf[:2] in {...}``) hashes the whole object the view was made from, a millisecond
    for a 1080p image.
    """
    if len(buf) < HEADER_SIZE or buf[0] != 0:
        return None
    kind = buf[1]
    if kind == CDR_LE[1]:
        return True
    if kind == CDR_BE[1]:
        return False
    return None


class _Walker:
    def __init__(self, buf: memoryview, *, little_endian: bool) -> None:
        self.buf = buf
        self.little_endian = little_endian
        self._u32 = struct.Struct("<I" if little_endian else ">I")
        self.pos = HEADER_SIZE

    def walk(self, layout: Layout) -> BulkLocation | None:
        for field in layout:
            if isinstance(field, str) and field in _TOKEN_SIZES:
                size = _TOKEN_SIZES[field]
                self.pos = self._aligned(size)
                self._advance(size)
            elif field == "str":
                self._advance(self._count())
            elif field == "bulk":
                length_at = self.pos = self._aligned(4)
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

    def _aligned(self, size: int) -> int:
        return self.pos + (-(self.pos - HEADER_SIZE) % size)

    def _count(self) -> int:
        self.pos = self._aligned(4)
        self._advance(4)
        value: int = self._u32.unpack_from(self.buf, self.pos - 4)[0]
        return value

    def _advance(self, size: int) -> None:
        self.pos += size
        if self.pos > len(self.buf):
            msg = f"serialized ROS message of {len(self.buf)} bytes ends inside a field"
            raise ConversionError(msg)

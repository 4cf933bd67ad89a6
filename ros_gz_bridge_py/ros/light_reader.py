"""Read serialized ROS messages into light attribute trees, for ROS -> Gazebo channels.

rclpy turns each received message into Python message objects: every nested message is a
class instance built through its ``__init__``, every fixed array a numpy array. For a
20-transform TFMessage that is ~300 µs, for an Odometry ~40 µs, more than the conversion to
protobuf that follows. The converters only read attributes, so a ROS -> Gazebo channel
subscribes to the serialized message instead and reads it here into
:class:`types.SimpleNamespace` trees with the same attribute names (numbers as ``int``/
``float``/``bool``, strings as ``str``, numeric arrays and sequences as tuples, ``uint8``/
``byte`` ones as ``bytes``, nested sequences as lists): several times cheaper.

The encoding read is stated in docs/cdr.md §1-§3. A reader is compiled once per message class
from rclpy's own type description (``get_fields_and_field_types`` and ``SLOT_TYPES``). Classic
little-endian CDR only: a message in another encapsulation, and a type with ``wstring``,
``wchar`` or ``long double``, is left to rclpy (:func:`reader_for` returns None, :func:`read`
returns None).
"""

from __future__ import annotations

import struct
from collections.abc import Callable
from types import SimpleNamespace
from typing import Any

from ros_gz_bridge_py.errors import ConversionError
from ros_gz_bridge_py.ros.cdr_types import (
    BASIC,
    BODY,
    BYTE_TYPES,
    CDR_LE_HEADER,
    SEQUENCE_TYPES,
    STRING_TYPES,
    basic_of,
    fields_of,
    nested_class,
)

#: Reads one value at a position of the buffer; returns it and the position after it.
Reader = Callable[[bytes, int], tuple[Any, int]]

_CDR_LE = CDR_LE_HEADER[:2]
_U32 = struct.Struct("<I")


class _UnreadableTypeError(Exception):
    """A type this module does not read (wide strings, long double)."""


def read(cdr: bytes, msg_class: type[Any]) -> Any | None:
    """The message in ``cdr`` as an attribute tree, or None if rclpy must read it.

    Raises:
        ConversionError: the serialized message is shorter than its type or malformed.
    """
    reader = reader_for(msg_class)
    if reader is None or cdr[:2] != _CDR_LE:
        return None
    try:
        return reader(cdr, BODY)[0]
    except (struct.error, UnicodeDecodeError, IndexError) as err:
        name = msg_class.__name__
        msg = f"serialized {name} of {len(cdr)} bytes is malformed: {err}"
        raise ConversionError(msg) from err


_READERS: dict[type[Any], Reader | None] = {}


def reader_for(msg_class: type[Any]) -> Reader | None:
    """The compiled reader of ``msg_class`` (built once), or None if a field type is not
    supported."""
    if msg_class not in _READERS:
        try:
            _READERS[msg_class] = _struct_reader(msg_class)
        except _UnreadableTypeError:
            _READERS[msg_class] = None
    return _READERS[msg_class]


def _struct_reader(msg_class: type[Any]) -> Reader:
    fields = fields_of(msg_class)
    if not fields:  # an empty message still carries one uint8 on the wire
        return _empty_reader
    steps = _merge_basic_runs(fields)
    make = SimpleNamespace

    def read_struct(buf: bytes, pos: int) -> tuple[Any, int]:
        values: dict[str, Any] = {}
        for step in steps:
            pos = step(buf, pos, values)
        return make(**values), pos

    return read_struct


def _empty_reader(buf: bytes, pos: int) -> tuple[Any, int]:
    """A message with no field: its one byte on the wire (docs/cdr.md §2) must be there."""
    if pos >= len(buf):
        msg = "the message's one byte is missing"
        raise IndexError(msg)
    return SimpleNamespace(), pos + 1


#: One step of a struct reader: reads one or more fields into ``values``; returns the position.
Step = Callable[[bytes, int, dict[str, Any]], int]


def _merge_basic_runs(fields: list[tuple[str, Any]]) -> list[Step]:
    """Steps for the fields; consecutive basic fields of one size become one ``unpack``."""
    steps: list[Step] = []
    run: list[tuple[str, str]] = []
    run_size = 0
    for name, slot in fields:
        basic = basic_of(slot)
        if basic is not None and basic in BASIC and basic != "octet":
            size, code = BASIC[basic]
            if run and size != run_size:
                steps.append(_basic_run_step(run, run_size))
                run = []
            run.append((name, code))
            run_size = size
            continue
        if run:
            steps.append(_basic_run_step(run, run_size))
            run = []
        steps.append(_field_step(name, _value_reader(slot)))
    if run:
        steps.append(_basic_run_step(run, run_size))
    return steps


def _basic_run_step(run: list[tuple[str, str]], size: int) -> Step:
    names = [name for name, _ in run]
    unpack = struct.Struct("<" + "".join(code for _, code in run)).unpack_from
    length = size * len(run)

    def step(buf: bytes, pos: int, values: dict[str, Any]) -> int:
        pos += -(pos - BODY) % size
        values.update(zip(names, unpack(buf, pos), strict=True))
        return pos + length

    return step


def _field_step(name: str, reader: Reader) -> Step:
    def step(buf: bytes, pos: int, values: dict[str, Any]) -> int:
        values[name], pos = reader(buf, pos)
        return pos

    return step


def _value_reader(slot: Any) -> Reader:
    kind = type(slot).__name__
    if kind == "BasicType":
        return _basic_reader(slot.typename)
    if kind in STRING_TYPES:
        return _read_string
    if kind == "NamespacedType":
        return _nested_reader(slot)
    if kind == "Array":
        return _array_reader(slot.value_type, slot.size)
    if kind in SEQUENCE_TYPES:
        return _sequence_reader(slot.value_type)
    raise _UnreadableTypeError(kind)


def _basic_reader(typename: str) -> Reader:
    if typename not in BASIC:
        raise _UnreadableTypeError(typename)
    size, code = BASIC[typename]
    unpack = struct.Struct("<" + code).unpack_from

    def read_basic(buf: bytes, pos: int) -> tuple[Any, int]:
        pos += -(pos - BODY) % size
        return unpack(buf, pos)[0], pos + size

    return read_basic


def _read_string(buf: bytes, pos: int) -> tuple[str, int]:
    """A CDR string as rclpy reads it: its bytes up to the first NUL (the one that ends it,
    or one inside), all of them when the last is not a NUL; a length of 0 is ''."""
    pos += -(pos - BODY) % 4
    (length,) = _U32.unpack_from(buf, pos)
    pos += 4
    end = pos + length
    if end > len(buf):
        msg = f"string of {length} bytes at offset {pos}"
        raise IndexError(msg)
    nul = buf.find(0, pos, end)
    return buf[pos : end if nul < 0 else nul].decode(), end


def _nested_reader(slot: Any) -> Reader:
    return _struct_reader(nested_class(slot))


def _array_reader(value_type: Any, count: int) -> Reader:
    basic = basic_of(value_type)
    if basic is not None:
        return _basic_block_reader(basic, lambda _buf, pos: (count, pos))
    element = _value_reader(value_type)
    return _element_list_reader(element, lambda _buf, pos: (count, pos))


def _sequence_reader(value_type: Any) -> Reader:
    basic = basic_of(value_type)
    if basic is not None:
        return _basic_block_reader(basic, _read_count)
    return _element_list_reader(_value_reader(value_type), _read_count)


def _read_count(buf: bytes, pos: int) -> tuple[int, int]:
    pos += -(pos - BODY) % 4
    return _U32.unpack_from(buf, pos)[0], pos + 4


def _basic_block_reader(typename: str, count_of: Callable[[bytes, int], tuple[int, int]]) -> Reader:
    if typename not in BASIC:
        raise _UnreadableTypeError(typename)
    size, code = BASIC[typename]
    as_bytes = typename in BYTE_TYPES

    def read_block(buf: bytes, pos: int) -> tuple[Any, int]:
        count, pos = count_of(buf, pos)
        if count == 0:
            return (b"" if as_bytes else ()), pos
        pos += -(pos - BODY) % size
        end = pos + size * count
        if end > len(buf):
            msg = f"{count} x {typename} at offset {pos}"
            raise IndexError(msg)
        if as_bytes:
            return buf[pos:end], end
        return struct.unpack_from(f"<{count}{code}", buf, pos), end

    return read_block


def _element_list_reader(
    element: Reader, count_of: Callable[[bytes, int], tuple[int, int]]
) -> Reader:
    def read_list(buf: bytes, pos: int) -> tuple[Any, int]:
        count, pos = count_of(buf, pos)
        if count > len(buf):
            msg = f"sequence of {count} elements in {len(buf)} bytes"
            raise IndexError(msg)
        items = []
        for _ in range(count):
            item, pos = element(buf, pos)
            items.append(item)
        return items, pos

    return read_list

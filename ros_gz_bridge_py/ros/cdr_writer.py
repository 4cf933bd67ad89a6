"""Serialize ROS messages to CDR in Python, for Gazebo -> ROS channels of small messages.

rclpy's ``Publisher.publish`` converts the Python message into a C struct, serializes it and
writes it with the GIL held. The bytes this module writes are published instead through
``rcl_publish_serialized_message`` with the GIL released (``SerializedPublisher``), and the
writer itself costs half of rclpy's conversion and serialization or less (Odometry ~5 µs
against ~12 µs).

A writer is compiled once per message class from rclpy's own type description: Python source
with one statement per field, consecutive basic fields of one size packed by one
``struct.Struct``, alignment padding left out wherever the offset is known when compiling (a
``Pose`` after a ``Header`` is padded once, not seven times). It reads each field from the
slot behind rclpy's property (``m._x``: the getter is a Python call that only returns it), so
a message's nested messages must be of their declared classes, as rclpy's own publish requires
too. Numeric arrays are written as one block (numpy arrays and ``array.array`` through ``tobytes``).

It writes what rclpy writes (docs/cdr.md §2-§4; tests compare every pair's ROS type byte for
byte; rclpy leaves padding bytes uninitialised, this module writes zeros). A value it cannot
write exactly as rclpy would (a number out of range, a list of the wrong length) raises from
the writer;
:class:`~ros_gz_bridge_py.ros.serialized_publisher.WrittenPublisher` then publishes that
message through rclpy, so the message is published or refused exactly as before. A type with a
field it does not write (``char``, wide strings) has no writer. Little-endian hosts only.
"""

from __future__ import annotations

import keyword
import struct
import sys
from array import array
from collections.abc import Callable
from typing import Any

from ros_gz_bridge_py.ros import cdr_types as cdr

#: Serializes one message to CDR bytes (with the encapsulation header).
Writer = Callable[[Any], bytes]

#: Basic types the writer handles (``char`` is left to rclpy: its Python type varies).
_WRITABLE = {name: spec for name, spec in cdr.BASIC.items() if name != "char"}
_U32 = struct.Struct("<I").pack


class _UnwritableTypeError(Exception):
    """A field type this module does not write."""


def writer_for(msg_class: type[Any]) -> Writer | None:
    """The compiled writer of ``msg_class`` (built once), or None where rclpy must write it."""
    if msg_class not in _WRITERS:
        try:
            _WRITERS[msg_class] = _compile(msg_class) if sys.byteorder == "little" else None
        except _UnwritableTypeError:
            _WRITERS[msg_class] = None
    return _WRITERS[msg_class]


_WRITERS: dict[type[Any], Writer | None] = {}


def numeric_block(values: Any, code: str, count: int | None) -> bytes:
    """A numeric array or sequence as little-endian bytes of struct ``code``.

    ``count``: the length a fixed array must have; None for a sequence.

    Raises:
        ValueError: a fixed array of another length, or a container of another element type.
    """
    if count is not None and len(values) != count:
        msg = f"array of {len(values)} elements where {count} are declared"
        raise ValueError(msg)
    if isinstance(values, (bytes, bytearray)) and code in "Bc":
        return bytes(values)
    np = sys.modules.get("numpy")  # an ndarray exists only once numpy is imported
    if np is not None and isinstance(values, np.ndarray):
        if values.dtype != np.dtype(code) and values.dtype.kind != np.dtype(code).kind:
            msg = f"numpy array of {values.dtype} where {np.dtype(code)} is declared"
            raise ValueError(msg)
        block: bytes = values.astype(code, copy=False).tobytes()
        return block
    if isinstance(values, array) and values.typecode == code:
        return values.tobytes()
    if code == "c":
        return b"".join(values)
    return struct.pack(f"<{len(values)}{code}", *values)


class _Source:
    """The Python source of one writer under construction.

    ``known``/``rem``: what the compiler knows of the write position (counted from the end of
    the encapsulation header): ``position % known == rem``. Padding to an alignment up to
    ``known`` is written as constant bytes (or not at all); above it, computed at run time.
    """

    def __init__(self) -> None:
        self.lines: list[str] = []
        self.constants: dict[str, object] = {}
        self.known = 8
        self.rem = 0
        self._names = 0

    def name(self, prefix: str) -> str:
        self._names += 1
        return f"{prefix}{self._names}"

    def constant(self, value: object) -> str:
        name = self.name("_k")
        self.constants[name] = value
        return name

    def emit(self, line: str, indent: int) -> None:
        self.lines.append("    " * indent + line)

    def align(self, size: int, indent: int) -> None:
        if size <= 1:
            return
        if size <= self.known:
            pad = -self.rem % size
            if pad:
                self.emit(f"b += {bytes(pad)!r}", indent)
                self.rem = (self.rem + pad) % self.known
            return
        self.emit(f"b += _ZEROS[:({cdr.BODY} - len(b)) % {size}]", indent)
        self.known, self.rem = size, 0

    def advance(self, length: int) -> None:
        self.rem = (self.rem + length) % self.known

    def forget(self, known: int = 1) -> None:
        """After a variable-length field: only ``position % known == 0`` is known."""
        self.known, self.rem = known, 0


def _compile(msg_class: type[Any]) -> Writer:
    source = _Source()
    source.emit("def write(m):", 0)
    source.emit(f"b = bytearray({cdr.CDR_LE_HEADER!r})", 1)
    _struct(source, msg_class, "m", 1)
    source.emit("return bytes(b)", 1)
    namespace: dict[str, Any] = {
        "_ZEROS": bytes(8),
        "_U32": _U32,
        "_block": numeric_block,
        **source.constants,
    }
    code = compile("\n".join(source.lines), f"<cdr writer {msg_class.__name__}>", "exec")
    exec(code, namespace)  # noqa: S102 - the source names only fields checked in _struct
    writer: Writer = namespace["write"]
    return writer


def _struct(source: _Source, msg_class: type[Any], expr: str, indent: int) -> None:
    fields = cdr.fields_of(msg_class)
    if not fields:  # an empty message still carries one uint8 on the wire
        source.emit("b += b'\\x00'", indent)
        source.advance(1)
        return
    run: list[tuple[str, str]] = []
    run_size = 0
    for name, slot in fields:
        if not name.isidentifier() or keyword.iskeyword(name):
            raise _UnwritableTypeError(name)
        value = f"{expr}.{_stored(msg_class, name)}"
        basic = cdr.basic_of(slot)
        if basic is not None:
            size, code = _basic(basic)
            if run and size != run_size:
                _pack_run(source, run, run_size, indent)
                run = []
            run.append((value, code))
            run_size = size
            continue
        if run:
            _pack_run(source, run, run_size, indent)
            run = []
        _field(source, slot, value, indent)
    if run:
        _pack_run(source, run, run_size, indent)


def _stored(msg_class: type[Any], name: str) -> str:
    """Where ``msg_class`` keeps field ``name``: its slot ``_name`` behind the property
    ``name`` in rclpy's classes (read directly: the property getter is a Python call per field,
    that only returns the slot), else the attribute ``name`` itself."""
    slot = f"_{name}"
    if isinstance(getattr(msg_class, name, None), property) and slot in getattr(
        msg_class, "__slots__", ()
    ):
        return slot
    return name


def _basic(typename: str) -> tuple[int, str]:
    if typename not in _WRITABLE:
        raise _UnwritableTypeError(typename)
    return _WRITABLE[typename]


def _pack_run(source: _Source, run: list[tuple[str, str]], size: int, indent: int) -> None:
    pack = source.constant(struct.Struct("<" + "".join(code for _, code in run)).pack)
    source.align(size, indent)
    source.emit(f"b += {pack}({', '.join(value for value, _ in run)})", indent)
    source.advance(size * len(run))


def _field(source: _Source, slot: Any, expr: str, indent: int) -> None:
    kind = type(slot).__name__
    if kind in cdr.STRING_TYPES:
        _string(source, expr, getattr(slot, "maximum_size", None), indent)
    elif kind == "NamespacedType":
        value = source.name("v")
        source.emit(f"{value} = {expr}", indent)
        _struct(source, cdr.nested_class(slot), value, indent)
    elif kind == "Array":
        _elements(source, slot.value_type, expr, slot.size, indent)
    elif kind in cdr.SEQUENCE_TYPES:
        values = source.name("s")
        source.emit(f"{values} = {expr}", indent)
        bound = getattr(slot, "maximum_size", None)
        if bound:
            source.emit(f"if len({values}) > {bound}:", indent)
            source.emit(f"raise ValueError('sequence longer than its bound {bound}')", indent + 1)
        source.align(4, indent)
        source.emit(f"b += _U32(len({values}))", indent)
        source.advance(4)
        _elements(source, slot.value_type, values, None, indent)
    else:
        raise _UnwritableTypeError(kind)


def _string(source: _Source, expr: str, bound: int | None, indent: int) -> None:
    text = source.name("t")
    source.emit(f"{text} = {expr}.encode()", indent)
    if bound:
        source.emit(f"if len({expr}) > {bound}:", indent)
        source.emit(f"raise ValueError('string longer than its bound {bound}')", indent + 1)
    source.align(4, indent)
    source.emit(f"b += _U32(len({text}) + 1)", indent)
    source.emit(f"b += {text}", indent)
    source.emit("b += b'\\x00'", indent)
    source.forget()


def _elements(source: _Source, slot: Any, expr: str, count: int | None, indent: int) -> None:
    """The elements of an array (``count`` of them) or of a sequence (its count written)."""
    basic = cdr.basic_of(slot)
    if basic is not None:
        size, code = _basic(basic)
        if count is not None:
            source.align(size, indent)
            source.emit(f"b += _block({expr}, {code!r}, {count})", indent)
            source.advance(size * count)
            return
        # A sequence follows its uint32 count; Fast CDR aligns its elements only when there
        # are some, which matters for 8-byte elements alone.
        if size > 4:
            source.emit(f"if len({expr}):", indent)
            source.emit(f"b += _ZEROS[:({cdr.BODY} - len(b)) % {size}]", indent + 1)
        source.emit(f"b += _block({expr}, {code!r}, None)", indent)
        source.forget(min(size, 4))
        return
    if count is not None:
        source.emit(f"if len({expr}) != {count}:", indent)
        source.emit(f"raise ValueError('array of another length than {count}')", indent + 1)
    item = source.name("e")
    source.emit(f"for {item} in {expr}:", indent)
    source.forget()
    _field(source, slot, item, indent + 1)
    source.forget()

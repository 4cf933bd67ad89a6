"""Compile a pair's declaration into the words of a native ROS -> Gazebo encoder
(docs/native.md §6).

As for the Gazebo -> ROS programs (``program.py``), the words are read from the converters'
declarations: the ``to_gz`` halves of the :func:`~ros_gz_bridge_py.converters._fields.fields`
tables, a few hand-written leaves named in :data:`_LEAVES` beside what they do, the ROS type
description (the CDR the read ops walk) and the protobuf descriptors (field numbers and types
of the message the write ops write). The write ops write what the Python runtime would
serialize after the Python converter ran: fields in number order, a submessage whenever a field
of it was assigned (even to its default), a scalar only when it is not zero.
"""

from __future__ import annotations

from array import array
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from typing import Any

from ros_gz_bridge_py.converters._fields import Each, gz_declaration_of
from ros_gz_bridge_py.converters.builtin_interfaces import fill_gz_present_time
from ros_gz_bridge_py.converters.covariance import fill_gz_covariance
from ros_gz_bridge_py.converters.registry import Pair
from ros_gz_bridge_py.converters.std_msgs import (
    CHILD_FRAME_ID_KEY,
    FRAME_ID_KEY,
    FRAMES,
    HEADER,
)
from ros_gz_bridge_py.msgs import message_class
from ros_gz_bridge_py.native import words
from ros_gz_bridge_py.native.codes import Conv, PbType, ReadOp, RosKind, WriteOp
from ros_gz_bridge_py.native.words import (
    LENGTH_DELIMITED,
    Half,
    NotExpressibleError,
    Path,
    ros_kind,
    text_words,
)
from ros_gz_bridge_py.ros import cdr_types as cdr


@dataclass
class Copy:
    """The gz field takes the ROS field at ``ros`` (``wrap``: C integer narrowing)."""

    ros: Path
    wrap: bool = False


@dataclass
class Text:
    """A constant string (a header entry's key)."""

    value: str


@dataclass
class Node:
    """A gz submessage the converter writes into (so present on the wire): per field name, a
    source, a Node, or a list of them for a repeated field."""

    fields: dict[str, Any] = field(default_factory=dict)

    def at(self, path: Path) -> Node:
        """The Node at ``path`` below this one (made present)."""
        node = self
        for name in path:
            child = node.fields.get(name)
            if not isinstance(child, Node):
                child = node.fields[name] = Node()
            node = child
        return node

    def set(self, path: Path, source: Any) -> None:
        self.at(path[:-1]).fields[path[-1]] = source

    def append(self, path: Path, item: Any) -> None:
        items = self.at(path[:-1]).fields.setdefault(path[-1], [])
        if not isinstance(items, list):
            msg = f"{'.'.join(path)} written as a single and a repeated field"
            raise NotExpressibleError(msg)
        items.append(item)


@dataclass
class Sequence:
    """A repeated gz message, one element per item of the ROS sequence at ``ros``."""

    ros: Path
    element: Node


@dataclass
class Packed:
    """A repeated gz number field from the ROS array or sequence at ``ros``."""

    ros: Path


def _entry_node(key: str, ros: Path) -> Node:
    """A gz ``Header.Map`` entry: ``key`` and the ROS string at ``ros`` as its one value."""
    return Node({"key": Text(key), "value": [Copy(ros)]})


def _time(ros: Path, gz: Path, out: Node) -> None:
    out.at(gz)
    out.set((*gz, "sec"), Copy((*ros, "sec")))
    out.set((*gz, "nsec"), Copy((*ros, "nanosec"), wrap=True))


def _header(ros: Path, gz: Path, out: Node) -> None:
    """``fill_gz_header``: the stamp (present), then one ``frame_id`` entry."""
    _time((*ros, "stamp"), (*gz, "stamp"), out)
    out.append((*gz, "data"), _entry_node(FRAME_ID_KEY, (*ros, "frame_id")))


def _frames(ros: Path, gz: Path, out: Node) -> None:
    _header((*ros, "header"), (*gz, "header"), out)
    out.append((*gz, "header", "data"), _entry_node(CHILD_FRAME_ID_KEY, (*ros, "child_frame_id")))


def _covariance(ros: Path, gz: Path, out: Node) -> None:
    """``fill_gz_covariance``: the Float_V present, every value in ``data``."""
    out.at(gz).fields["data"] = Packed(ros)


#: The hand-written Fills the tables build on, by their ``to_gz`` half.
_LEAVES: dict[Callable[[Any, Any], None], Callable[[Path, Path, Node], None]] = {
    fill_gz_present_time: _time,
    HEADER.to_gz: _header,
    FRAMES.to_gz: _frames,
    fill_gz_covariance: _covariance,
}


def _copy(ros: Path, gz: Path, wrap: bool, out: Node) -> None:
    out.set(gz, Copy(ros, wrap))


def _each(shape: Each, ros: Path, gz: Path, out: Node) -> None:
    element = Node()
    _TO_GZ.assign(shape.fill, (), (), element)
    out.set(gz, Sequence(ros, element))


def _clock(out: Node) -> None:
    """``clock_to_gz``: the clock as the (present) ``sim`` time."""
    _time(("clock",), ("sim",), out)


#: Whole hand-written converters, by module and name (not imported: see program.py).
_WHOLE: dict[tuple[str, str], Callable[[Node], None]] = {
    ("ros_gz_bridge_py.converters.rosgraph_msgs", "clock_to_gz"): _clock,
}


_TO_GZ = Half("to_gz", _LEAVES, _copy, _each, _WHOLE)


# ---- the ROS side: read ops and slots ---------------------------------------------------------


class _Frame:
    """The slots of one frame (the message, or one element of a message sequence)."""

    def __init__(self, used: set[Path]) -> None:
        self.used = used
        self.slots: dict[Path, int] = {}
        self.kinds: dict[Path, Any] = {}
        self.elements: dict[Path, _Frame] = {}

    def slot(self, path: Path, rosidl: Any) -> int:
        if path not in self.used:
            return -1
        self.slots[path] = len(self.slots)
        self.kinds[path] = rosidl
        return self.slots[path]


def _sources(node: Node) -> Iterator[Any]:
    """Every source below ``node``, in the order of its fields (a sequence's, not its
    elements')."""
    for value in node.fields.values():
        for item in value if isinstance(value, list) else [value]:
            if isinstance(item, Node):
                yield from _sources(item)
            else:
                yield item


def _used(node: Node) -> set[Path]:
    """Every ROS path ``node``'s sources read (a sequence's own path, not its elements')."""
    return {item.ros for item in _sources(node) if isinstance(item, (Copy, Sequence, Packed))}


def _read_ops(
    msg_class: type[Any], prefix: Path, frame: _Frame, elements: dict[Path, Node]
) -> list[int]:
    ops: list[int] = []
    fields = cdr.fields_of(msg_class)
    if not fields:
        return [ReadOp.NUM, RosKind.UINT8, -1]
    for name, rosidl in fields:
        path = (*prefix, name)
        kind = type(rosidl).__name__
        basic = cdr.basic_of(rosidl)
        if basic is not None:
            ops += [ReadOp.NUM, ros_kind(rosidl)[0], frame.slot(path, rosidl)]
        elif kind in cdr.STRING_TYPES:
            ops += [ReadOp.STR, frame.slot(path, rosidl)]
        elif kind == "NamespacedType":
            ops += _read_ops(cdr.nested_class(rosidl), path, frame, elements)
        elif kind == "Array" and cdr.basic_of(rosidl.value_type) is not None:
            ops += [ReadOp.ARR, ros_kind(rosidl.value_type)[0], rosidl.size,
                    frame.slot(path, rosidl)]  # fmt: skip
        elif kind in cdr.SEQUENCE_TYPES and cdr.basic_of(rosidl.value_type) is not None:
            ops += [ReadOp.SEQ_NUM, ros_kind(rosidl.value_type)[0], frame.slot(path, rosidl)]
        elif kind in cdr.SEQUENCE_TYPES and type(rosidl.value_type).__name__ in cdr.STRING_TYPES:
            ops += [ReadOp.SEQ_STR, frame.slot(path, rosidl)]
        elif kind in cdr.SEQUENCE_TYPES and type(rosidl.value_type).__name__ == "NamespacedType":
            element_node = elements.get(path, Node())
            element = _Frame(_used(element_node))
            body = _read_ops(
                cdr.nested_class(rosidl.value_type), (), element, _sequences(element_node)
            )
            body.append(ReadOp.END)
            slot = frame.slot(path, rosidl)
            frame.elements[path] = element
            ops += [ReadOp.SEQ_MSG, slot, len(element.slots), len(body), *body]
        else:
            msg = f"a ROS {kind} field ({'.'.join(path)}) the encoder does not read"
            raise NotExpressibleError(msg)
    return ops


def _sequences(node: Node) -> dict[Path, Node]:
    """The element Node of each ROS sequence ``node``'s sources read."""
    return {item.ros: item.element for item in _sources(node) if isinstance(item, Sequence)}


# ---- the gz side: write ops ---------------------------------------------------------------------


def _write_ops(node: Node, descriptor: Any, frame: _Frame) -> list[int]:
    ops: list[int] = []
    ordered = sorted(
        node.fields.items(), key=lambda item: words.gz_field(descriptor, item[0]).number
    )
    for name, value in ordered:
        field = words.gz_field(descriptor, name)
        for item in value if isinstance(value, list) else [value]:
            ops += _write_one(item, field, frame, repeated=isinstance(value, list))
    return ops


def _write_one(item: Any, gz_field: Any, frame: _Frame, *, repeated: bool) -> list[int]:
    number = gz_field.number
    if isinstance(item, Node):
        if gz_field.message_type is None or gz_field.is_repeated != repeated:
            msg = f"{gz_field.full_name} is not a message field"
            raise NotExpressibleError(msg)
        body = _write_ops(item, gz_field.message_type, frame)
        body.append(WriteOp.END)
        return [WriteOp.MSG, number, len(body), *body]
    if isinstance(item, Text):
        if gz_field.type != PbType.STRING or gz_field.is_repeated:
            msg = f"{gz_field.full_name} is not a string"
            raise NotExpressibleError(msg)
        return [WriteOp.CONST_STR, number, *text_words(item.value.encode())]
    if isinstance(item, Sequence):
        element = frame.elements.get(item.ros)
        if element is None or gz_field.message_type is None or not gz_field.is_repeated:
            msg = f"{gz_field.full_name} from {'.'.join(item.ros)}: not a repeated message"
            raise NotExpressibleError(msg)
        body = _write_ops(item.element, gz_field.message_type, element)
        body.append(WriteOp.END)
        return [WriteOp.SEQ_MSG, number, frame.slots[item.ros], len(element.slots), len(body),
                *body]  # fmt: skip
    if isinstance(item, Packed):
        rosidl = frame.kinds[item.ros]
        if not gz_field.is_repeated or gz_field.type in LENGTH_DELIMITED:
            msg = f"{gz_field.full_name} is not a repeated number"
            raise NotExpressibleError(msg)
        kind = ros_kind(rosidl.value_type)[0]
        _check_number(gz_field, kind)
        return [WriteOp.PACKED, number, gz_field.type, kind, frame.slots[item.ros]]
    if isinstance(item, Copy):
        rosidl = frame.kinds[item.ros]
        slot = frame.slots[item.ros]
        if type(rosidl).__name__ in cdr.STRING_TYPES:
            if gz_field.type != PbType.STRING:
                msg = f"{gz_field.full_name} is not a string"
                raise NotExpressibleError(msg)
            return [WriteOp.STR_REP if repeated else WriteOp.STR, number, slot]
        if repeated or gz_field.is_repeated:
            msg = f"{gz_field.full_name}: one number into a repeated field"
            raise NotExpressibleError(msg)
        kind = ros_kind(rosidl)[0]
        _check_number(gz_field, kind)
        return [
            WriteOp.NUM,
            number,
            gz_field.type,
            kind,
            Conv.WRAP if item.wrap else Conv.EXACT,
            slot,
        ]
    msg = f"{type(item).__name__} into {gz_field.full_name}"
    raise NotExpressibleError(msg)


_FLOAT_KINDS = frozenset({RosKind.FLOAT, RosKind.DOUBLE})


def _check_number(gz_field: Any, kind: int) -> None:
    """Only what Python assigns without a conversion of its own: floats into float fields,
    booleans into bool fields, integers into integer fields."""
    floats = gz_field.type in (PbType.DOUBLE, PbType.FLOAT)
    boolean = kind == RosKind.BOOLEAN
    if floats != (kind in _FLOAT_KINDS) or (gz_field.type == PbType.BOOL) != boolean:
        msg = f"{gz_field.full_name} from a ROS number of another sort"
        raise NotExpressibleError(msg)
    if gz_field.type in (*LENGTH_DELIMITED, PbType.GROUP):
        msg = f"{gz_field.full_name} is not a number"
        raise NotExpressibleError(msg)


def compile_to_gz(pair: Pair) -> bytes:
    """The words of the encoder from ``pair``'s ROS messages (CDR) to its Gazebo payloads.

    Raises:
        NotExpressibleError: the pair stays on the Python path (the reason says why).
    """
    tree = Node()
    _TO_GZ.read(pair, gz_declaration_of(pair.to_gz), tree)
    top = _Frame(_used(tree))
    read = _read_ops(pair.ros_class, (), top, _sequences(tree))
    read.append(ReadOp.END)
    write = _write_ops(tree, message_class(pair.gz_type).DESCRIPTOR, top)
    write.append(WriteOp.END)
    return array("i", [len(top.slots), len(read), *read, *write]).tobytes()

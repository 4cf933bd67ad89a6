"""Compile a pair's declaration into the words of a native program (docs/native.md §2-§3).

The program is read from what the converters are declared with, not written a second time:
the :func:`~ros_gz_bridge_py.converters._fields.fields` tables (``Fill.shape``) say which
Gazebo field each ROS field comes from; the ROS type description (rclpy's, as the CDR writer
reads it) gives the wire order and types; the protobuf descriptors give field numbers and
types. The few hand-written pieces the tables build on (times, headers, covariances, the Clock
and JointState converters) are named in :data:`_LEAVES` and :data:`_WHOLE`, each beside the
native op that does the same; tests compare the bytes of both paths for every pair that
compiles. Anything else (a Value of another function, a Fill of hand-written code, a default
the program cannot write) makes the pair :class:`NotExpressible`: it stays on the Python path.
"""

from __future__ import annotations

import struct
from array import array
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

from ros_gz_bridge_py.converters._fields import Each, declaration_of
from ros_gz_bridge_py.converters.builtin_interfaces import fill_ros_time
from ros_gz_bridge_py.converters.covariance import fill_ros_covariance
from ros_gz_bridge_py.converters.registry import Pair
from ros_gz_bridge_py.converters.std_msgs import (
    CHILD_FRAME_ID_KEY,
    FRAME_ID_KEY,
    FRAMES,
    HEADER,
)
from ros_gz_bridge_py.msgs import message_class
from ros_gz_bridge_py.native.codes import Conv, Op, PbType, RosKind
from ros_gz_bridge_py.native.words import (
    LENGTH_DELIMITED,
    Half,
    NotExpressibleError,
    Path,
    descend,
    ros_kind,
    text_words,
    walk,
)
from ros_gz_bridge_py.ros import cdr_types as cdr

#: Most fields a message of the schema may have (transcode.c keeps one bit per field).
_MAX_FIELDS = 64


@dataclass(frozen=True)
class Copy:
    """The ROS field takes the Gazebo field at ``gz`` (``wrap``: with C integer narrowing)."""

    gz: Path
    wrap: bool = False


@dataclass(frozen=True)
class HeaderText:
    """A string from the gz Header at ``gz``: the first or last ``data`` entry named ``key``
    that has a value, its first value with ``::`` as ``/`` (``std_msgs.py``)."""

    gz: Path
    key: str
    last: bool


@dataclass(frozen=True)
class FixedList:
    """A fixed ROS array from the repeated gz field at ``gz``: its values when there are as
    many, else zeros (``fill_ros_covariance``)."""

    gz: Path


@dataclass(frozen=True)
class Sequence:
    """A ROS sequence of messages, one per element of the repeated gz field at ``gz``."""

    gz: Path
    element: Mapping[Path, Source]
    new_ros: Callable[[], Any]


@dataclass(frozen=True)
class Column:
    """A ROS sequence of plain values: the field ``field`` of each element of the repeated gz
    field at ``gz`` (``joint_state_to_ros``)."""

    gz: Path
    field: Path


@dataclass(frozen=True)
class ClockPart:
    """Seconds (0) or nanoseconds (1) of ``clock_to_ros``'s normalised time at ``gz``."""

    gz: Path
    part: int


@dataclass(frozen=True)
class FixedText:
    """A constant string: the channel's ``frame_id`` (the header rewrite of ``gz_to_ros.py``)."""

    value: str


@dataclass(frozen=True)
class WallStamp:
    """The wall clock when the message is written: seconds (part 0, which writes both parts,
    as ``override_timestamps_with_wall_time`` reads the clock once) or nanoseconds (1)."""

    part: int


Source = Copy | HeaderText | FixedList | Sequence | Column | ClockPart | FixedText | WallStamp
Assignments = dict[Path, Source]


def _time(ros: Path, gz: Path, out: Assignments) -> None:
    """``fill_ros_time``: both parts narrowed as C++ does."""
    out[(*ros, "sec")] = Copy((*gz, "sec"), wrap=True)
    out[(*ros, "nanosec")] = Copy((*gz, "nsec"), wrap=True)


def _header(ros: Path, gz: Path, out: Assignments) -> None:
    """``fill_ros_header``: the stamp and the last ``frame_id`` entry."""
    _time((*ros, "stamp"), (*gz, "stamp"), out)
    out[(*ros, "frame_id")] = HeaderText(gz, FRAME_ID_KEY, last=True)


def _frames(ros: Path, gz: Path, out: Assignments) -> None:
    """``FRAMES``: the header, and the first ``child_frame_id`` entry."""
    _header((*ros, "header"), (*gz, "header"), out)
    out[(*ros, "child_frame_id")] = HeaderText((*gz, "header"), CHILD_FRAME_ID_KEY, last=False)


def _covariance(ros: Path, gz: Path, out: Assignments) -> None:
    out[ros] = FixedList((*gz, "data"))


#: The hand-written Fills the tables build on, by their ``to_ros`` half.
_LEAVES: dict[Callable[[Any, Any], None], Callable[[Path, Path, Assignments], None]] = {
    fill_ros_time: _time,
    HEADER.to_ros: _header,
    FRAMES.to_ros: _frames,
    fill_ros_covariance: _covariance,
}


def _joint_state(out: Assignments) -> None:
    _header(("header",), ("header",), out)
    out[("name",)] = Column(("joint",), ("name",))
    out[("position",)] = Column(("joint",), ("axis1", "position"))
    out[("velocity",)] = Column(("joint",), ("axis1", "velocity"))
    out[("effort",)] = Column(("joint",), ("axis1", "force"))


def _clock(out: Assignments) -> None:
    out[("clock", "sec")] = ClockPart(("sim",), 0)
    out[("clock", "nanosec")] = ClockPart(("sim",), 1)


#: Whole hand-written converters, by the module and name of their ``to_ros`` (named, not
#: imported: the registry imports a converter module only when a pair of it is used).
_WHOLE: dict[tuple[str, str], Callable[[Assignments], None]] = {
    ("ros_gz_bridge_py.converters.rosgraph_msgs", "clock_to_ros"): _clock,
    ("ros_gz_bridge_py.converters.sensor_msgs", "joint_state_to_ros"): _joint_state,
}


def _copy(ros: Path, gz: Path, wrap: bool, out: Assignments) -> None:
    out[ros] = Copy(gz, wrap)


def _each(shape: Each, ros: Path, gz: Path, out: Assignments) -> None:
    element: Assignments = {}
    _TO_ROS.assign(shape.fill, (), (), element)
    out[ros] = Sequence(gz, element, shape.new_ros)


#: Where each ROS field written by a Fill's ``to_ros`` comes from (later entries win, as they do
#: when the Python code runs).
_TO_ROS = Half("to_ros", _LEAVES, _copy, _each, _WHOLE)


# ---- the schema ------------------------------------------------------------------------------


class _Schema:
    """The Gazebo message types a payload may hold, numbered from the root (index 0)."""

    def __init__(self, root: Any) -> None:
        self.index: dict[str, int] = {}
        self.messages: list[Any] = []
        self.of(root)

    def of(self, descriptor: Any) -> int:
        name = descriptor.full_name
        if name not in self.index:
            self.index[name] = len(self.messages)
            self.messages.append(descriptor)
            for field in descriptor.fields:
                if field.message_type is not None:
                    self.of(field.message_type)
        return self.index[name]

    def words(self) -> list[int]:
        count = len(self.messages)
        head = [count]
        body: list[int] = []
        for descriptor in self.messages:
            head.append(1 + count + len(body))
            fields = list(descriptor.fields)
            if len(fields) > _MAX_FIELDS:
                msg = f"{descriptor.full_name} has more than {_MAX_FIELDS} fields"
                raise NotExpressibleError(msg)
            body.append(len(fields))
            for field in fields:
                if field.type == PbType.GROUP:
                    msg = f"group field {descriptor.full_name}.{field.name}"
                    raise NotExpressibleError(msg)
                sub = self.index[field.message_type.full_name] if field.message_type else -1
                body += [field.number, field.type, int(field.is_repeated), sub]
        return head + body


# ---- ops -------------------------------------------------------------------------------------


def _bits(code: str, value: Any) -> tuple[int, int]:
    raw = struct.pack(f"<{code}", value).ljust(8, b"\0")
    lo, hi = struct.unpack("<ii", raw)
    return lo, hi


def _scalar_field(field: Any) -> None:
    if field.is_repeated or field.type in (*LENGTH_DELIMITED, PbType.GROUP):
        msg = f"{field.full_name} is not a plain scalar"
        raise NotExpressibleError(msg)


def _message(
    msg_class: type[Any], prefix: Path, given: Mapping[Path, Source], default: Any,
    gz: Any,
) -> list[int]:  # fmt: skip
    fields = cdr.fields_of(msg_class)
    if not fields:
        return [Op.CONST, RosKind.UINT8, 0, 0]
    ops: list[int] = []
    for name, slot in fields:
        path = (*prefix, name)
        value = getattr(default, name)
        source = given.get(path)
        if source is not None:
            ops += _source(slot, source, value, gz)
        elif type(slot).__name__ == "NamespacedType":
            nested = {key: src for key, src in given.items() if key[: len(path)] == path}
            ops += _message(cdr.nested_class(slot), path, nested, value, gz)
        else:
            ops += _constant(slot, value)
    return ops


def _source(slot: Any, source: Source, default: Any, gz: Any) -> list[int]:
    kind = type(slot).__name__
    if isinstance(source, Copy) and kind in cdr.STRING_TYPES:
        steps, field = walk(gz, source.gz)
        if field.type != PbType.STRING or field.is_repeated:
            msg = f"{field.full_name} is not a string"
            raise NotExpressibleError(msg)
        return [Op.STR, len(steps), *steps, field.number]
    if isinstance(source, Copy):
        steps, field = walk(gz, source.gz)
        _scalar_field(field)
        kind_number, code = ros_kind(slot)
        if code in "fd" and field.cpp_type not in (5, 6):  # CPPTYPE_DOUBLE, CPPTYPE_FLOAT
            msg = f"{field.full_name} is not a floating-point number"
            raise NotExpressibleError(msg)
        conv = Conv.WRAP if source.wrap else Conv.EXACT
        return [Op.NUM, len(steps), *steps, field.number, field.type, kind_number, conv]
    if isinstance(source, HeaderText) and kind in cdr.STRING_TYPES:
        steps, _header_type = descend(gz, source.gz)
        return [
            Op.HEADER_STR, len(steps), *steps, int(source.last),
            *text_words(source.key.encode()), *text_words(_plain(default)),
        ]  # fmt: skip
    if isinstance(source, FixedList) and kind == "Array":
        steps, field = walk(gz, source.gz)
        if not field.is_repeated or field.type in LENGTH_DELIMITED:
            msg = f"{field.full_name} is not a repeated number"
            raise NotExpressibleError(msg)
        kind_number, _code = ros_kind(slot.value_type)
        return [Op.FIXED_LIST, len(steps), *steps, field.number, field.type, kind_number,
                slot.size]  # fmt: skip
    if isinstance(source, Sequence) and kind in cdr.SEQUENCE_TYPES:
        steps, field = walk(gz, source.gz)
        element_class = cdr.nested_class(slot.value_type)
        if field.message_type is None or not field.is_repeated:
            msg = f"{field.full_name} is not a repeated message"
            raise NotExpressibleError(msg)
        body = _message(element_class, (), source.element, source.new_ros(), field.message_type)
        body.append(Op.END)
        return [Op.SEQ_MSG, len(steps), *steps, field.number, len(body), *body]
    if isinstance(source, Column) and kind in cdr.SEQUENCE_TYPES:
        steps, field = walk(gz, source.gz)
        if field.message_type is None or not field.is_repeated:
            msg = f"{field.full_name} is not a repeated message"
            raise NotExpressibleError(msg)
        sub_steps, sub = walk(field.message_type, source.field)
        head = [len(steps), *steps, field.number, len(sub_steps), *sub_steps, sub.number]
        if type(slot.value_type).__name__ in cdr.STRING_TYPES and sub.type == PbType.STRING:
            return [Op.COLUMN_STR, *head]
        _scalar_field(sub)
        kind_number, _code = ros_kind(slot.value_type)
        return [Op.COLUMN, *head, sub.type, kind_number]
    if isinstance(source, ClockPart) and cdr.basic_of(slot) is not None:
        steps, _time_type = descend(gz, source.gz)
        return [Op.CLOCK, len(steps), *steps, source.part]
    if isinstance(source, FixedText) and kind in cdr.STRING_TYPES:
        return [Op.CONST_STR, *text_words(_plain(source.value))]
    if isinstance(source, WallStamp) and cdr.basic_of(slot) in ("int32", "uint32"):
        return [Op.WALL_STAMP] if source.part == 0 else []
    msg = f"{type(source).__name__} into a ROS {kind}"
    raise NotExpressibleError(msg)


def _constant(slot: Any, value: Any) -> list[int]:
    """The ops that write ``value``, a ROS field's default."""
    kind = type(slot).__name__
    if cdr.basic_of(slot) is not None:
        kind_number, code = ros_kind(slot)
        return [Op.CONST, kind_number, *_bits(code, value)]
    if kind in cdr.STRING_TYPES:
        return [Op.CONST_STR, *text_words(_plain(value))]
    if kind == "Array" and cdr.basic_of(slot.value_type) is not None:
        _kind_number, code = ros_kind(slot.value_type)
        data = struct.pack(f"<{slot.size}{code}", *value)
        return [Op.CONST_BLOCK, struct.calcsize(code), *text_words(data)]
    if kind in cdr.SEQUENCE_TYPES and len(value) == 0:
        return [Op.CONST, RosKind.UINT32, 0, 0]
    msg = f"a default {kind} the program cannot write"
    raise NotExpressibleError(msg)


def _plain(text: str) -> bytes:
    data = text.encode()
    if b"\0" in data:
        msg = "a default string with a NUL"
        raise NotExpressibleError(msg)
    return data


@dataclass(frozen=True)
class Compiled:
    """The words of one pair's program: the schema of its Gazebo type, then the ops."""

    schema: bytes
    ops: bytes


def compile_to_ros(pair: Pair, *, frame_id: str = "", wall_stamp: bool = False) -> Compiled:
    """The program converting ``pair``'s Gazebo messages to its ROS messages' CDR.

    ``frame_id`` and ``wall_stamp``: the header rewrite a channel applies to a message with a
    top-level ``std_msgs/Header`` (``frame_id``, ``override_timestamps_with_wall_time``);
    nothing for other messages, as in ``gz_to_ros.py``.

    Raises:
        NotExpressibleError: the pair stays on the Python path (the reason says why).
    """
    declared = declaration_of(pair.to_ros)
    given: Assignments = {}
    _TO_ROS.read(pair, declared[0] if declared else None, given)
    default = declared[1]() if declared else pair.ros_class()
    if pair.ros_class.get_fields_and_field_types().get("header") == "std_msgs/Header":
        if frame_id:
            given[("header", "frame_id")] = FixedText(frame_id)
        if wall_stamp:
            given[("header", "stamp", "sec")] = WallStamp(0)
            given[("header", "stamp", "nanosec")] = WallStamp(1)
    root = message_class(pair.gz_type).DESCRIPTOR
    schema = _Schema(root)
    ops = _message(pair.ros_class, (), given, default, root)
    ops.append(Op.END)
    return Compiled(array("i", schema.words()).tobytes(), array("i", ops).tobytes())

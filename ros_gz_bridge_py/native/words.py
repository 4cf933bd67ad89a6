"""What the two compilers of native programs share (``program.py``: Gazebo -> ROS,
``encoder.py``: ROS -> Gazebo): the error that keeps a pair on the Python path, paths of field
names, the ROS basic types by name (their numbers, as all of the programs' numbers, are
``codes.py``'s), the walk of a declaration's Fills and the Value functions a program expresses
in it, text as words, and the protobuf fields and ROS slots they read.
"""

from __future__ import annotations

import sys
from array import array
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Generic, TypeVar

from ros_gz_bridge_py.converters._fields import Each, Fill, Table, same
from ros_gz_bridge_py.converters.builtin_interfaces import to_int32, to_uint32
from ros_gz_bridge_py.native.codes import PbType, RosKind
from ros_gz_bridge_py.ros import cdr_types as cdr

if TYPE_CHECKING:
    from ros_gz_bridge_py.converters.registry import Pair

#: Protobuf field types whose values are bytes (length-delimited), not numbers.
LENGTH_DELIMITED = frozenset({PbType.STRING, PbType.MESSAGE, PbType.BYTES})
#: ROS basic types as the program numbers them, with their struct codes.
ROS_KINDS: dict[str, tuple[RosKind, str]] = {
    "boolean": (RosKind.BOOLEAN, "?"),
    "uint8": (RosKind.UINT8, "B"),
    "octet": (RosKind.UINT8, "B"),
    "int8": (RosKind.INT8, "b"),
    "int16": (RosKind.INT16, "h"),
    "uint16": (RosKind.UINT16, "H"),
    "int32": (RosKind.INT32, "i"),
    "uint32": (RosKind.UINT32, "I"),
    "int64": (RosKind.INT64, "q"),
    "uint64": (RosKind.UINT64, "Q"),
    "float": (RosKind.FLOAT, "f"),
    "double": (RosKind.DOUBLE, "d"),
}


class NotExpressibleError(Exception):
    """The pair's conversion has a step a native program cannot express."""


Path = tuple[str, ...]


def split_path(path: str) -> Path:
    return tuple(path.split(".")) if path else ()


#: The Value functions programs express, and whether each narrows as C++ does.
VALUES: dict[Callable[[Any], Any], bool] = {same: False, to_int32: True, to_uint32: True}


_T = TypeVar("_T")


@dataclass(frozen=True)
class Half(Generic[_T]):
    """How a compiler reads one half (``to_ros`` or ``to_gz``) of the declarations into its
    ``_T``: ``leaves``, the hand-written Fills the tables build on; ``copy(ros, gz, wrap, out)``
    for a field copied (``wrap``: narrowed as C++ does); ``each(shape, ros, gz, out)`` for a
    sequence filled element by element; ``whole``, whole hand-written converters by module and
    name (:func:`named`)."""

    name: str
    leaves: Mapping[Callable[[Any, Any], None], Callable[[Path, Path, _T], None]]
    copy: Callable[[Path, Path, bool, _T], None]
    each: Callable[[Each, Path, Path, _T], None]
    whole: Mapping[tuple[str, str], Callable[[_T], None]]

    def assign(self, fill: Fill, ros: Path, gz: Path, out: _T) -> None:
        """What ``fill``'s half writes (from ``gz`` to ``ros`` or back), into ``out``; raises
        NotExpressibleError at a step a program cannot express."""
        function = getattr(fill, self.name)
        leaf = self.leaves.get(function)
        if leaf is not None:
            leaf(ros, gz, out)
        elif isinstance(fill.shape, Table):
            for ros_path, gz_path, how in fill.shape.parts:
                at = (*ros, *split_path(ros_path)), (*gz, *split_path(gz_path))
                step = same if how is None else getattr(how, self.name)  # a Value's, or None
                if isinstance(how, Fill):
                    self.assign(how, *at, out)
                elif step in VALUES:
                    self.copy(*at, VALUES[step], out)
                elif step is not None:
                    msg = f"a Value of {step.__qualname__}"
                    raise NotExpressibleError(msg)
        elif isinstance(fill.shape, Each):
            self.each(fill.shape, ros, gz, out)
        else:
            msg = f"a Fill of hand-written functions ({function.__qualname__})"
            raise NotExpressibleError(msg)

    def read(self, pair: Pair, fill: Fill | None, out: _T) -> None:
        """What ``pair``'s converter of this half writes, into ``out``: its declaration
        ``fill``, or else a whole hand-written converter; raises NotExpressibleError for a bulk
        pair or other hand-written code."""
        function = getattr(pair, self.name)
        if pair.bulk is not None:
            msg = "a bulk pair (it has its own path)"
            raise NotExpressibleError(msg)
        if fill is not None:
            self.assign(fill, (), (), out)
        elif (converter := named(function, self.whole)) is not None:
            converter(out)
        else:
            msg = f"a hand-written converter ({function.__qualname__})"
            raise NotExpressibleError(msg)


def named(function: Callable[..., Any], table: Mapping[tuple[str, str], _T]) -> _T | None:
    """``table``'s entry for ``function``, keyed by its module and name (the function itself,
    not another of the same name)."""
    key = (getattr(function, "__module__", ""), getattr(function, "__qualname__", ""))
    module = sys.modules.get(key[0])
    if key not in table or getattr(module, key[1], None) is not function:
        return None
    return table[key]


def text_words(data: bytes) -> list[int]:
    """A byte string as words: its length, then the bytes four to a word."""
    padded = data + bytes(-len(data) % 4)
    return [len(data), *array("i", padded)]


def gz_field(descriptor: Any, name: str) -> Any:
    """The field ``name`` of a protobuf message ``descriptor``."""
    field = descriptor.fields_by_name.get(name)
    if field is None:
        msg = f"{descriptor.full_name} has no field {name!r}"
        raise NotExpressibleError(msg)
    return field


def descend(descriptor: Any, path: Path) -> tuple[list[int], Any]:
    """The field numbers of the submessages on ``path``, and the message it reaches."""
    steps = []
    for name in path:
        field = gz_field(descriptor, name)
        if field.message_type is None or field.is_repeated:
            msg = f"{descriptor.full_name}.{name} is not a singular submessage"
            raise NotExpressibleError(msg)
        steps.append(field.number)
        descriptor = field.message_type
    return steps, descriptor


def walk(descriptor: Any, path: Path) -> tuple[list[int], Any]:
    """The field numbers of the submessages on ``path`` (all but the last name), and the
    descriptor of the field the last name names."""
    steps, parent = descend(descriptor, path[:-1])
    return steps, gz_field(parent, path[-1])


def ros_kind(slot: Any) -> tuple[RosKind, str]:
    """The program's number and the struct code of a ROS basic type."""
    basic = cdr.basic_of(slot)
    if basic not in ROS_KINDS:
        msg = f"ROS type {basic or type(slot).__name__} is not written natively"
        raise NotExpressibleError(msg)
    return ROS_KINDS[basic]

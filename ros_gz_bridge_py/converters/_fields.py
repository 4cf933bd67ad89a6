"""One declaration for both directions: fills and tables of fields.

Most conversions are a list of field copies that would be written twice, R→G and G→R, the
second a mirror of the first. Here the list is written once. A :class:`Fill` holds both
directions of one conversion into an existing message; :func:`fields` makes the Fill that goes
through a table of fields, each copied as it is, through a :class:`Value` function, or through
another Fill (a submessage); :func:`each` and :func:`repeated` are the Fills of lists.
:func:`converters` and :func:`fill_pair` turn a Fill into whole-message converters and a pair.
Each direction of a table compiles to the straight-line function one would write by hand, so
vectors and quaternions are tables too; leaves that are not lists of fields (headers, times,
covariances) stay plain functions, wrapped in a Fill.
"""

from __future__ import annotations

import keyword
from array import array
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

from ros_gz_bridge_py.converters._limits import check_list, fill_bounded, least_item_bytes
from ros_gz_bridge_py.converters.registry import Pair
from ros_gz_bridge_py.msgs import message_class
from ros_gz_bridge_py.ros.constructors import constructor

#: The path of a message itself: ``("pose", WHOLE, POSE)`` fills the whole gz message from the
#: ROS ``pose`` (a Stamped body), and back.
WHOLE = ""


@dataclass(frozen=True)
class Fill:
    """Both directions of a conversion into an existing message.

    ``to_gz(ros, gz)`` writes ROS ``ros`` into gz ``gz``; ``to_ros(gz, ros)`` writes back
    (source first, as the ``fill_*`` functions and the C++ ``convert_*`` functions).
    """

    to_gz: Callable[[Any, Any], None]
    to_ros: Callable[[Any, Any], None]
    #: What the Fill is made of, for those that read declarations instead of running them
    #: (the native programs, ``native/program.py``): a :class:`Table` or an :class:`Each`;
    #: None for a Fill of hand-written functions.
    shape: Table | Each | None = field(default=None, compare=False)


@dataclass(frozen=True)
class Table:
    """The entries of a :func:`fields` Fill: (ROS path, gz path, how) each, in order."""

    parts: tuple[tuple[str, str, Fill | Value | None], ...]


@dataclass(frozen=True)
class Each:
    """The Fill of each element of an :func:`each` list, and the maker of new ROS items."""

    fill: Fill
    new_ros: Callable[[], Any]


@dataclass(frozen=True)
class Value:
    """A field's value converted on the way: ``to_gz(ros_value)``, ``to_ros(gz_value)``.

    None: that direction leaves the target field alone.
    """

    to_gz: Callable[[Any], Any] | None
    to_ros: Callable[[Any], Any] | None


def same(value: Any) -> Any:
    """The value as it is (a :class:`Value` direction that converts nothing)."""
    return value


#: Copied R→G only; G→R leaves the ROS field alone.
TO_GZ_ONLY = Value(same, None)


#: A table entry: a field name both sides share; ``(ros_path, gz_path)``; either with a Fill
#: or Value as ``(name, how)`` / ``(ros_path, gz_path, how)``; or a Fill of the whole messages.
#: Paths may be dotted (``"body_1_name.data"``).
Entry = str | tuple[str, str] | tuple[str, Fill | Value] | tuple[str, str, Fill | Value] | Fill


def fields(*entries: Entry) -> Fill:
    """The Fill that converts every entry in order, R→G and G→R alike.

    Each direction is compiled once into one straight-line function (``gz.linear.x =
    ros.linear.x`` and so on, the Fills and Values called directly), as fast as the same
    conversion written by hand.
    """
    parts = tuple(_parts(entry) for entry in entries)
    to_gz = _compile("to_gz", [(ros, gz, how, _TO_GZ) for ros, gz, how in parts])
    to_ros = _compile("to_ros", [(gz, ros, how, _TO_ROS) for ros, gz, how in parts])
    return Fill(to_gz, to_ros, Table(parts))


def each(fill: Fill, new_ros: Callable[[], Any]) -> Fill:
    """The Fill of a list of submessages: one gz element added per ROS item, and the ROS list
    replaced by one new item (``new_ros()``) per gz element, unless that list would be an
    amplification (``_limits.check_list``: refused with a ConversionError)."""
    new_ros = _fast(new_ros)
    measured: list[tuple[int, str]] = []  # an item's fewest CDR bytes and type, on first use

    def to_gz(ros_items: Any, gz_items: Any) -> None:
        for item in ros_items:
            fill.to_gz(item, gz_items.add())

    def to_ros(gz_items: Any, ros_items: Any) -> None:
        if not measured:
            measured.append((least_item_bytes(new_ros), type(new_ros()).__name__))
        check_list(gz_items, *measured[0])
        ros_items[:] = [_filled(fill, element, new_ros()) for element in gz_items]

    return Fill(to_gz, to_ros, Each(fill, new_ros))


def repeated(read: Callable[[Any], Any]) -> Fill:
    """The Fill of a list of plain values: R→G extends the gz repeated field; G→R replaces the
    ROS list (or array) by ``read(gz_values)``."""

    def to_gz(ros_values: Any, gz_values: Any) -> None:
        gz_values.extend(ros_values)

    def to_ros(gz_values: Any, ros_values: Any) -> None:
        ros_values[:] = read(gz_values)

    return Fill(to_gz, to_ros)


def numbers(typecode: str) -> Fill:
    """:func:`repeated` for a ROS ``array(typecode)``; numpy reads the gz repeated field as one
    buffer (~300x faster than iterating it). numpy is imported by the modules that declare
    such a list, not by every converter module."""
    import numpy as np  # noqa: PLC0415

    return repeated(lambda values: array(typecode, np.asarray(values, dtype=typecode).tobytes()))


#: :func:`repeated` for a ROS ``string[]``.
STRINGS = repeated(list)


def _fast(new_ros: Callable[[], Any]) -> Callable[[], Any]:
    """``new_ros``, or for a message class the faster :func:`constructor` of the same object."""
    return constructor(new_ros) if isinstance(new_ros, type) else new_ros


def _filled(fill: Fill, gz: Any, ros: Any) -> Any:
    fill.to_ros(gz, ros)
    return ros


def converters(
    fill: Fill, new_ros: Callable[[], Any], gz_type: str
) -> tuple[Callable[[Any], Any], Callable[[Any], Any]]:
    """``to_gz(ros)`` and ``to_ros(gz)``: each fills a new message of the other side.

    ``new_ros`` makes the new ROS message: its class, or a function that presets the fields the
    gz message does not carry.
    """
    gz_class = message_class(gz_type)
    new_ros = _fast(new_ros)

    def to_gz(ros: Any) -> Any:
        gz = gz_class()
        fill.to_gz(ros, gz)
        return gz

    def to_ros(gz: Any) -> Any:
        ros = new_ros()
        fill.to_ros(gz, ros)
        return ros

    def to_ros_with_lists(gz: Any) -> Any:
        ros = new_ros()
        fill_bounded(fill.to_ros, gz, ros)  # its lists are bounded by gz's size
        return ros

    if _has_list(fill):
        to_ros = to_ros_with_lists
    _DECLARED[to_ros] = (fill, new_ros)
    _DECLARED_TO_GZ[to_gz] = fill
    return to_gz, to_ros


def _has_list(fill: Fill) -> bool:
    """Whether the Fill converts a list of submessages (:func:`each`), at any depth."""
    if isinstance(fill.shape, Each):
        return True
    if isinstance(fill.shape, Table):
        return any(isinstance(how, Fill) and _has_list(how) for _ros, _gz, how in fill.shape.parts)
    return False


#: The Fill and ROS message maker behind each ``to_ros`` that :func:`converters` made.
_DECLARED: dict[Callable[[Any], Any], tuple[Fill, Callable[[], Any]]] = {}


#: The Fill behind each ``to_gz`` that :func:`converters` made.
_DECLARED_TO_GZ: dict[Callable[[Any], Any], Fill] = {}


def declaration_of(to_ros: Callable[[Any], Any]) -> tuple[Fill, Callable[[], Any]] | None:
    """The Fill and the ROS message maker a ``to_ros`` converter was made of, if
    :func:`converters` made it."""
    return _DECLARED.get(to_ros)


def gz_declaration_of(to_gz: Callable[[Any], Any]) -> Fill | None:
    """The Fill a ``to_gz`` converter was made of, if :func:`converters` made it."""
    return _DECLARED_TO_GZ.get(to_gz)


def fill_pair(
    ros_class: type[Any], gz_type: str, fill: Fill, *, default_for_gz_type: bool = False
) -> Pair:
    """The :meth:`Pair.of` whose converters are ``fill`` into a new message (:func:`converters`)."""
    to_gz, to_ros = converters(fill, ros_class, gz_type)
    return Pair.of(ros_class, gz_type, to_gz, to_ros, default_for_gz_type=default_for_gz_type)


#: Which half of a Fill or Value an entry uses in each direction.
_TO_GZ, _TO_ROS = "to_gz", "to_ros"


def _compile(
    name: str, steps: list[tuple[str, str, Fill | Value | None, str]]
) -> Callable[[Any, Any], None]:
    """``name(source, target)`` doing each step: (source path, target path, how, direction)."""
    lines = [f"def {name}(source, target):"]
    constants: dict[str, Any] = {}
    for index, (source_path, target_path, how, direction) in enumerate(steps):
        source, target = _path("source", source_path), _path("target", target_path)
        if how is None:
            lines.append(f"    {target} = {source}")
            continue
        convert = getattr(how, direction)
        if convert is None:  # a Value that leaves this direction alone
            continue
        constants[f"_{index}"] = convert
        if isinstance(how, Fill):
            lines.append(f"    _{index}({source}, {target})")
        elif convert is same:
            lines.append(f"    {target} = {source}")
        else:
            lines.append(f"    {target} = _{index}({source})")
    lines.append("    return None")
    code = compile("\n".join(lines), f"<fields {name}>", "exec")
    exec(code, constants)  # noqa: S102 - the source names only paths checked by _path
    function: Callable[[Any, Any], None] = constants[name]
    return function


def _path(root: str, path: str) -> str:
    """``root.a.b`` for the dotted ``path`` (``root`` for WHOLE).

    Raises:
        ValueError: a part of ``path`` is not an attribute name.
    """
    names = path.split(".") if path else []
    for part in names:
        if not part.isidentifier() or keyword.iskeyword(part):
            msg = f"field path {path!r} has a part that is not an attribute name"
            raise ValueError(msg)
    return ".".join([root, *names])


def _parts(entry: Entry) -> tuple[str, str, Fill | Value | None]:
    """(ROS path, gz path, how) of a table entry."""
    if isinstance(entry, str):
        return entry, entry, None
    if isinstance(entry, Fill):
        return WHOLE, WHOLE, entry
    if len(entry) == 3:
        return entry
    first, second = entry
    if isinstance(second, str):
        return first, second, None
    return first, first, second

"""One declaration for both directions: fills and tables of fields.

Most conversions are a list of field copies that would be written twice, R→G and G→R, the
second a mirror of the first. Here the list is written once. A :class:`Fill` holds both
directions of one conversion into an existing message; :func:`fields` makes the Fill that goes
through a table of fields, each copied as it is, through a :class:`Value` function, or through
another Fill (a submessage); :func:`each` and :func:`repeated` are the Fills of lists.
:func:`converters` and :func:`fill_pair` turn a Fill into whole-message converters and a pair.
Hot leaves (vectors, quaternions, headers) stay plain functions, wrapped in a Fill: as tables
they would cost a quarter more on TF and Twist.
"""

from __future__ import annotations

from array import array
from collections.abc import Callable
from dataclasses import dataclass
from operator import attrgetter
from typing import Any

import numpy as np

from ros_gz_bridge_py.converters.registry import Pair
from ros_gz_bridge_py.msgs import message_class

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
    """The Fill that converts every entry in order, R→G and G→R alike."""
    steps = [_steps(entry) for entry in entries]
    steps_to_gz = [to_gz for to_gz, _ in steps]
    steps_to_ros = [to_ros for _, to_ros in steps]

    def to_gz(ros: Any, gz: Any) -> None:
        for step in steps_to_gz:
            step(ros, gz)

    def to_ros(gz: Any, ros: Any) -> None:
        for step in steps_to_ros:
            step(gz, ros)

    return Fill(to_gz, to_ros)


def each(fill: Fill, new_ros: Callable[[], Any]) -> Fill:
    """The Fill of a list of submessages: one gz element added per ROS item, and the ROS list
    replaced by one new item (``new_ros()``) per gz element."""

    def to_gz(ros_items: Any, gz_items: Any) -> None:
        for item in ros_items:
            fill.to_gz(item, gz_items.add())

    def to_ros(gz_items: Any, ros_items: Any) -> None:
        ros_items[:] = [_filled(fill, element, new_ros()) for element in gz_items]

    return Fill(to_gz, to_ros)


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
    buffer (~300x faster than iterating it)."""
    return repeated(lambda values: array(typecode, np.asarray(values, dtype=typecode).tobytes()))


#: :func:`repeated` for a ROS ``string[]``.
STRINGS = repeated(list)


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

    def to_gz(ros: Any) -> Any:
        gz = gz_class()
        fill.to_gz(ros, gz)
        return gz

    def to_ros(gz: Any) -> Any:
        ros = new_ros()
        fill.to_ros(gz, ros)
        return ros

    return to_gz, to_ros


def fill_pair(
    ros_class: type[Any], gz_type: str, fill: Fill, *, default_for_gz_type: bool = False
) -> Pair:
    """The :meth:`Pair.of` whose converters are ``fill`` into a new message (:func:`converters`)."""
    to_gz, to_ros = converters(fill, ros_class, gz_type)
    return Pair.of(ros_class, gz_type, to_gz, to_ros, default_for_gz_type=default_for_gz_type)


#: One entry in one direction: ``step(source_message, target_message)``.
_Step = Callable[[Any, Any], None]


def _steps(entry: Entry) -> tuple[_Step, _Step]:
    """The entry's R→G and G→R steps."""
    ros_path, gz_path, how = _parts(entry)
    if isinstance(how, Fill):
        return _filling(ros_path, gz_path, how.to_gz), _filling(gz_path, ros_path, how.to_ros)
    if isinstance(how, Value):
        return _setting(ros_path, gz_path, how.to_gz), _setting(gz_path, ros_path, how.to_ros)
    return _setting(ros_path, gz_path, same), _setting(gz_path, ros_path, same)


def _parts(entry: Entry) -> tuple[str, str, Fill | Value | None]:
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


def _filling(source_path: str, target_path: str, fill: Callable[[Any, Any], None]) -> _Step:
    get_source, get_target = _getter(source_path), _getter(target_path)
    return lambda source, target: fill(get_source(source), get_target(target))


def _setting(source_path: str, target_path: str, convert: Callable[[Any], Any] | None) -> _Step:
    if convert is None:
        return _leave_alone
    get_source = _getter(source_path)
    parent, _, name = target_path.rpartition(".")
    get_parent = _getter(parent)
    if convert is same:
        return lambda source, target: setattr(get_parent(target), name, get_source(source))
    return lambda source, target: setattr(get_parent(target), name, convert(get_source(source)))


def _leave_alone(_source: Any, _target: Any) -> None:
    pass


def _getter(path: str) -> Callable[[Any], Any]:
    return attrgetter(path) if path else same

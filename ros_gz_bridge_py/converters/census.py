"""Counting a Gazebo message's lists before parsing it: a refusal that costs no parse.

A list of submessages is refused when its items would make a ROS message far larger than the
Gazebo message (``_limits.check_list``), but that check runs after the protobuf runtime has
parsed every element: a Pose_V of 4 M empty poses (8 MB) takes some 290 MB and 0.2 s to parse,
only to be refused. A :class:`ListCensus` parses the payload first with a class of its own, in
which each list of submessages at the top of the message is a list of ``bytes`` (and the rest
unknown fields): the same count for half the memory and time. Where the count times the
fewest bytes of an item passes the most the bound could allow (the native transcoder's rule,
docs/native.md §4: the message as protobuf re-encodes it is at most twice the payload), the
message is refused before it is parsed; otherwise it is parsed and converted as ever.
"""

from __future__ import annotations

import functools
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from google.protobuf import descriptor_pb2, descriptor_pool, message_factory

from ros_gz_bridge_py.converters._fields import Each, Table, declaration_of
from ros_gz_bridge_py.converters._limits import (
    MAX_OUTPUT,
    OUTPUT_FLOOR,
    OUTPUT_RATIO,
    amplification_error,
    least_item_bytes,
)
from ros_gz_bridge_py.msgs import message_class

_FIELD = descriptor_pb2.FieldDescriptorProto


@dataclass(frozen=True)
class CountedList:
    """One top-level list of submessages: its field, and the fewest bytes of its ROS item."""

    name: str
    number: int
    least: int
    item: str


class ListCensus:
    """The lists of one Gazebo type that a converter turns into ROS items (see the module)."""

    def __init__(self, gz_type: str, lists: tuple[CountedList, ...]) -> None:
        self.lists = lists
        self._class = _census_class(gz_type, lists)
        #: Below this payload size no list can pass the bound, whatever it holds (an element
        #: takes at least 2 bytes): no census is taken.
        self.needed_above = min(_size_needed(entry.least) for entry in lists)

    def check(self, payload: bytes | bytearray | memoryview) -> None:
        """Raises ConversionError where a list of ``payload`` is too large for certain.

        A payload the census class cannot parse is left to the real parse, which says why.
        """
        size = len(payload)
        if size <= self.needed_above:
            return
        try:
            counted = self._class.FromString(payload)
        except Exception:
            return
        most = _most_allowed(size)
        for entry in self.lists:
            count = len(getattr(counted, entry.name))
            if count * entry.least > most:
                raise amplification_error(count, f"{entry.item} items", size, count * entry.least)


def _most_allowed(size: int) -> int:
    """The most output the bound can allow a payload of ``size`` bytes (twice its size as
    protobuf re-encodes it at most: a negative int32 sent in 5 bytes takes 10)."""
    return min(OUTPUT_FLOOR + 2 * OUTPUT_RATIO * size, MAX_OUTPUT)


def _size_needed(least: int) -> int:
    """The largest payload in which no list of items of ``least`` bytes can pass the bound:
    ``size / 2`` elements at most, each ``least`` bytes, against :func:`_most_allowed`."""
    per_byte = least / 2 - 2 * OUTPUT_RATIO
    if per_byte <= 0:  # within the ratio whatever the count: only the cap can be passed
        return 2 * MAX_OUTPUT // max(least, 1)
    return min(int(OUTPUT_FLOOR / per_byte), 2 * MAX_OUTPUT // least)


def _census_class(gz_type: str, lists: tuple[CountedList, ...]) -> Any:
    """A protobuf class with each counted list as ``repeated bytes`` of the same number."""
    name = gz_type.replace(".", "_")
    proto = descriptor_pb2.FileDescriptorProto(
        name=f"census/{name}.proto", package="ros_gz_bridge_py.census", syntax="proto3"
    )
    message = proto.message_type.add(name=name)
    for entry in lists:
        message.field.add(name=entry.name, number=entry.number, type=_FIELD.TYPE_BYTES)
        message.field[-1].label = _FIELD.LABEL_REPEATED
    pool = descriptor_pool.DescriptorPool()
    pool.Add(proto)
    return message_factory.GetMessageClass(
        pool.FindMessageTypeByName(f"ros_gz_bridge_py.census.{name}")
    )


@functools.cache
def census_for(to_ros: Callable[[Any], Any], gz_type: str) -> ListCensus | None:
    """The census of a declared converter whose Gazebo message has lists of submessages at its
    top (None for any other: hand-written converters, and lists inside submessages, are only
    checked after the parse)."""
    declared = declaration_of(to_ros)
    if declared is None or not isinstance(declared[0].shape, Table):
        return None
    descriptor = message_class(gz_type).DESCRIPTOR
    lists = []
    for _ros_path, gz_path, how in declared[0].shape.parts:
        shape = getattr(how, "shape", None)
        if not isinstance(shape, Each) or gz_path not in descriptor.fields_by_name:
            continue
        number = descriptor.fields_by_name[gz_path].number
        item = type(shape.new_ros()).__name__
        lists.append(CountedList(gz_path, number, least_item_bytes(shape.new_ros), item))
    return ListCensus(gz_type, tuple(lists)) if lists else None

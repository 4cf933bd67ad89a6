"""How much larger than its Gazebo message a converted ROS message may be.

A list of submessages converts each Gazebo element into a ROS item with every field written,
so a list of empty elements (two bytes each on the wire) grows 28-40 times (TFMessage or
PoseArray from a Pose_V): anyone who can publish on a Gazebo topic could make the bridge build
a gigabyte from a few megabytes. Beyond ``OUTPUT_FLOOR`` bytes (the fixed part of any
message), a list may write at most ``OUTPUT_RATIO`` bytes per byte of the message it came
from; a larger one is refused before its items are made. The native transcoder applies the
same bound to its whole output (``RGB_OUTPUT_FLOOR``, ``RGB_OUTPUT_RATIO`` in native/wire.h;
docs/native.md §4), so what it writes Python accepts too. Whatever the message, no list may
write more than ``MAX_OUTPUT`` (``RGB_OUTPUT_MAX``): the largest Gazebo message the bridge
takes by default (``GZ_TRANSPORT_MAX_MESSAGE_SIZE``, 128 MiB), so the ROS messages it builds
are never larger than the largest it accepts (a 4K image of 8 bytes a pixel, 66 MB, takes the
bulk path and is not a list of items anyway).
"""

from __future__ import annotations

import threading
from collections.abc import Callable, Sized
from typing import Any

from ros_gz_bridge_py.errors import ConversionError
from ros_gz_bridge_py.ros.cdr_writer import writer_for

OUTPUT_FLOOR = 64 * 1024
OUTPUT_RATIO = 16
MAX_OUTPUT = 128 * 1024 * 1024
#: The CDR bytes of an item whose class rclpy must write: a guess on the small side.
_UNKNOWN_ITEM_BYTES = 8

#: The whole Gazebo message each thread is converting (see :func:`fill_bounded`).
_CONVERTING = threading.local()


def least_item_bytes(new_ros: Callable[[], Any]) -> int:
    """The CDR bytes of a default item (the fewest any item of its type writes)."""
    item = new_ros()
    writer = writer_for(type(item))
    if writer is None:
        return _UNKNOWN_ITEM_BYTES
    return max(1, len(writer(item)) - 4)  # without the encapsulation header


def fill_bounded(fill_to_ros: Callable[[Any, Any], None], gz: Any, ros: Any) -> None:
    """``fill_to_ros(gz, ros)``, with ``gz`` the message whose size bounds the lists in it."""
    outer = getattr(_CONVERTING, "message", None)
    _CONVERTING.message = gz
    try:
        fill_to_ros(gz, ros)
    finally:
        _CONVERTING.message = outer


def check_list(gz_items: Sized, least: int, ros_type: str) -> None:
    """Raises ConversionError when ``gz_items`` would become more than the bound allows."""
    count = len(gz_items)
    least_total = count * least
    if least_total <= OUTPUT_FLOOR:
        return
    message = getattr(_CONVERTING, "message", None)
    if message is not None:
        received = message.ByteSize()  # one pass in C
    else:  # a list converted outside a whole message: its elements, a tag and a length each
        received = sum(item.ByteSize() + 2 for item in gz_items)  # type: ignore[attr-defined]
    if least_total > _limit(received):
        raise amplification_error(count, f"{ros_type} items", received, least_total)


def check_output(count: int, item_bytes: int, items: str, received: int) -> None:
    """Raises ConversionError when ``count`` items of ``item_bytes`` each, made for a
    message of ``received`` bytes (a count it states, padded with zeros where its data is
    short), would be more than the bound allows."""
    least_total = count * item_bytes
    if least_total > OUTPUT_FLOOR and least_total > _limit(received):
        raise amplification_error(count, items, received, least_total)


def _limit(received: int) -> int:
    return min(OUTPUT_FLOOR + OUTPUT_RATIO * received, MAX_OUTPUT)


def amplification_error(count: int, items: str, received: int, least_total: int) -> ConversionError:
    """Why a list of ``count`` ``items`` (e.g. "Pose items") from a message of ``received``
    bytes, which would take at least ``least_total`` bytes, is refused (the native transcoder's
    refusals say the same, docs/native.md §4)."""
    limit = _limit(received)
    msg = (
        f"a list of {count} {items} from a message of {received} bytes would "
        f"take at least {least_total} bytes, over the limit of {limit} ({OUTPUT_FLOOR} + "
        f"{OUTPUT_RATIO} per byte received, at most {MAX_OUTPUT}): refused as an "
        "amplification; send elements with their fields set, or fewer of them"
    )
    return ConversionError(msg)

"""How much larger than its Gazebo message a converted ROS message may be.

A list of submessages converts each Gazebo element into a ROS item with every field written,
so a list of empty elements (two bytes each on the wire) grows 28-40 times (TFMessage or
PoseArray from a Pose_V): anyone who can publish on a Gazebo topic could make the bridge build
a gigabyte from a few megabytes. Beyond ``OUTPUT_FLOOR`` bytes (the fixed part of any
message), a list may write at most ``OUTPUT_RATIO`` bytes per byte it came from; a larger one
is refused before its items are made. The native transcoder applies the same bound to its
whole output (``RGB_OUTPUT_FLOOR``, ``RGB_OUTPUT_RATIO`` in native/wire.h; docs/native.md §4).
"""

from __future__ import annotations

from collections.abc import Callable, Sized
from typing import Any

from ros_gz_bridge_py.errors import ConversionError
from ros_gz_bridge_py.ros.cdr_writer import writer_for

OUTPUT_FLOOR = 64 * 1024
OUTPUT_RATIO = 16
#: The CDR bytes of an item whose class rclpy must write: a guess on the small side.
_UNKNOWN_ITEM_BYTES = 8


def least_item_bytes(new_ros: Callable[[], Any]) -> int:
    """The CDR bytes of a default item (the fewest any item of its type writes)."""
    item = new_ros()
    writer = writer_for(type(item))
    if writer is None:
        return _UNKNOWN_ITEM_BYTES
    return max(1, len(writer(item)) - 4)  # without the encapsulation header


def check_list(gz_items: Sized, least: int, ros_type: str) -> None:
    """Raises ConversionError when ``gz_items`` would become more than the bound allows."""
    count = len(gz_items)
    least_total = count * least
    if least_total <= OUTPUT_FLOOR:
        return
    # a tag and a length byte at least around each element
    wire = sum(item.ByteSize() + 2 for item in gz_items)  # type: ignore[attr-defined]
    limit = OUTPUT_FLOOR + OUTPUT_RATIO * wire
    if least_total > limit:
        msg = (
            f"a list of {count} {ros_type} items from {wire} bytes would take at least "
            f"{least_total} bytes, over the limit of {limit} ({OUTPUT_FLOOR} + {OUTPUT_RATIO} "
            "per byte received): refused as an amplification; send elements with their "
            "fields set, or fewer of them"
        )
        raise ConversionError(msg)

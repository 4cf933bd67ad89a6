"""A Gazebo -> ROS wire case (what a real publisher sends, what ROS must get) and the helpers
their texts and checks share (``wire_cases_*.py``, ``test_conversion_wire.py``); the sections
cited are those of docs/conversions.md and docs/conversions-per-package.md."""

from __future__ import annotations

import struct
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

SEC = 1_700_000_123
NSEC = 456_789_012


def header(frame: str, sec: int = SEC, nsec: int = NSEC, extra: str = "") -> str:
    """A text gz.msgs.Header with a ``seq`` entry first (ignored by the bridge, §1.3)."""
    return (
        f'header {{ stamp {{ sec: {sec} nsec: {nsec} }} data {{ key: "seq" value: "7" }} '
        f'data {{ key: "frame_id" value: "{frame}" }} {extra}}}'
    )


def assert_header(ros: Any, frame: str, sec: int = SEC, nsec: int = NSEC) -> None:
    assert ros.header.frame_id == frame
    assert (ros.header.stamp.sec, ros.header.stamp.nanosec) == (sec, nsec)


def xyz(vector: Any) -> tuple[float, float, float]:
    return (vector.x, vector.y, vector.z)


def xyzw(quaternion: Any) -> tuple[float, float, float, float]:
    return (quaternion.x, quaternion.y, quaternion.z, quaternion.w)


def f32(value: float) -> float:
    """``value`` rounded to float32, as a float32 ROS field holds it."""
    rounded: float = struct.unpack("<f", struct.pack("<f", value))[0]
    return rounded


def octal_bytes(data: bytes) -> str:
    """``data`` as a text-format string literal body (every byte an octal escape)."""
    return "".join(f"\\{byte:03o}" for byte in data)


@dataclass(frozen=True)
class Case:
    """One Gazebo -> ROS conversion: what the real publisher sends and what ROS must get."""

    name: str
    gz_type: str
    ros_type: str
    text: str
    check: Callable[[Any], None]
    #: Also published by the Debian CLI one-shot, not only by the C++ peer.
    cli: bool = False

"""Helpers of the image_bridge tests: the command line, test frames, the C++ peer's bytes."""

from __future__ import annotations

import sys
from collections.abc import Sequence
from typing import Any

from ros_gz_bridge_py.msgs import message_class

#: ``python -m`` form, the way the demo starts it (the console script runs the same ``main``).
IMAGE_BRIDGE = [sys.executable, "-m", "ros_gz_bridge_py.app.image_bridge"]
RGB_INT8 = 3
#: A gz PixelFormatType with no ROS encoding (RGB_INT32).
UNSUPPORTED_FORMAT = 7


def image_bridge_command(*args: str, ros_args: Sequence[str] = ()) -> list[str]:
    command = [*IMAGE_BRIDGE, *args]
    if ros_args:
        command += ["--ros-args", *ros_args]
    return command


def pattern_bytes(size: int) -> bytes:
    """The bytes the C++ peer's ``--bytes SIZE`` puts in ``data`` (its xorshift32 pattern)."""
    state = (0x9E3779B9 ^ size) & 0xFFFFFFFF
    out = bytearray(size)
    for index in range(size):
        state ^= (state << 13) & 0xFFFFFFFF
        state ^= state >> 17
        state ^= (state << 5) & 0xFFFFFFFF
        out[index] = state & 0xFF
    return bytes(out)


def rgb_frame(width: int, height: int, *, frame_id: str = "", data: bytes | None = None) -> Any:
    """A ``gz.msgs.Image`` RGB_INT8 frame; ``data`` defaults to the peer's pattern."""
    frame = message_class("gz.msgs.Image")()
    frame.width = width
    frame.height = height
    frame.step = width * 3
    frame.pixel_format_type = RGB_INT8
    frame.data = pattern_bytes(width * height * 3) if data is None else data
    if frame_id:
        entry = frame.header.data.add()
        entry.key = "frame_id"
        entry.value.append(frame_id)
    return frame


def rgb_text_proto(width: int, height: int, frame_id: str, *, seq: str = "") -> str:
    """The peer's TEXTPROTO argument for an RGB_INT8 frame (data comes from ``--bytes``); with
    ``seq``, the header a gz-sensors camera sends: a stamp, ``frame_id`` and ``seq``."""
    header = f'data {{ key: "frame_id" value: "{frame_id}" }}'
    if seq:
        header = f'stamp {{ sec: 812 nsec: 4000000 }} {header} data {{ key: "seq" value: "{seq}" }}'
    return (
        f"header {{ {header} }} "
        f"width: {width} height: {height} step: {width * 3} pixel_format_type: RGB_INT8"
    )


def camera_info(width: int, height: int) -> Any:
    """A ``gz.msgs.CameraInfo`` with intrinsics, as a gz-sensors camera sends it."""
    info = message_class("gz.msgs.CameraInfo")()
    info.width = width
    info.height = height
    info.intrinsics.k.extend([500.0, 0.0, width / 2, 0.0, 500.0, height / 2, 0.0, 0.0, 1.0])
    info.distortion.k.extend([0.1, 0.0, 0.0, 0.0, 0.0])
    return info

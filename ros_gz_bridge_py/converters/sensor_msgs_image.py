"""sensor_msgs Image and CameraInfo converters (docs/conversions-per-package.md §3.5); paired in
sensor_msgs.py.

Image data is copied once, as ``bytes``; on the bulk path (``IMAGE_BULK``) the channel converts
only the other fields with the ``*_meta_*`` halves and copies the data at most once.
Both paths check the sizes with the same ``*_meta_*`` code, so they reject the same messages
with the same text. The output always has step = width * bytes per pixel and exactly
height * step bytes of data; ``is_bigendian`` is ignored, as in the reference.

Differences from ros_gz_bridge:
- Image R→G with an unknown encoding raises ConversionError (C++ prints and publishes an
  image with format UNKNOWN_PIXEL_FORMAT and no data).
- Image R→G checks the ROS ``step``: less than width * bytes per pixel, or data shorter than
  height * step, raises ConversionError (C++ over-reads); a longer step is row padding, which
  is left out row by row (C++ ignores the step and shifts every row after the first).
- Image G→R with an unsupported format raises ConversionError (C++ prints and publishes an
  empty image); the gz ``step`` is ignored, as in C++; data shorter than height * width *
  bytes per pixel raises ConversionError (C++ publishes the frame zero-padded), and so does a
  width whose row does not fit the uint32 ROS ``step``.
- Longer data is truncated to height * step, both ways (C++ overruns G→R).
- CameraInfo G→R truncates gz arrays longer than the ROS k (9), p (12), r (9) arrays
  (C++ writes out of bounds).
"""

from __future__ import annotations

from typing import Any

from sensor_msgs.msg import CameraInfo, Image

from ros_gz_bridge_py.bulk.cdr import layout_until
from ros_gz_bridge_py.bulk.path import BulkPath, Rows, Take, taken
from ros_gz_bridge_py.converters._fields import fields
from ros_gz_bridge_py.converters.std_msgs import HEADER
from ros_gz_bridge_py.errors import ConversionError, SizeMismatchError
from ros_gz_bridge_py.msgs import message_class

GzImage = message_class("gz.msgs.Image")
GzCameraInfo = message_class("gz.msgs.CameraInfo")

#: ROS encoding -> (gz PixelFormatType value, channels, bytes per channel).
ENCODINGS: dict[str, tuple[int, int, int]] = {
    "mono8": (1, 1, 1),
    "mono16": (2, 1, 2),
    "rgb8": (3, 3, 1),
    "rgba8": (4, 4, 1),
    "bgra8": (5, 4, 1),
    "rgb16": (6, 3, 2),
    "bgr8": (8, 3, 1),
    "bgr16": (9, 3, 2),
    "32FC1": (13, 1, 4),
}
#: gz PixelFormatType value -> (ROS encoding, bytes per pixel); derived from ENCODINGS.
PIXEL_FORMATS: dict[int, tuple[str, int]] = {
    fmt: (encoding, channels * depth) for encoding, (fmt, channels, depth) in ENCODINGS.items()
}

#: gz PixelFormatType value -> its name (RGB_INT8), as the message schema declares them.
_FORMAT_NAMES: dict[int, str] = {
    number: value.name
    for number, value in GzImage.DESCRIPTOR.fields_by_name[
        "pixel_format_type"
    ].enum_type.values_by_number.items()
}

#: The formats that convert, by name, for the error that refuses another.
_SUPPORTED_FORMATS = ", ".join(_FORMAT_NAMES.get(fmt, str(fmt)) for fmt in PIXEL_FORMATS)

#: ROS distortion_model <-> gz CameraInfo.Distortion.DistortionModelType value.
DISTORTION_MODELS: dict[str, int] = {"plumb_bob": 0, "rational_polynomial": 1, "equidistant": 2}
_DISTORTION_NAMES = {value: name for name, value in DISTORTION_MODELS.items()}


#: What Image and CameraInfo both carry alike, on both sides.
_IMAGE_SIZE = fields(("header", HEADER), "height", "width")

#: The largest value of a uint32 field (``step`` on both sides).
UINT32_MAX = 2**32 - 1


def image_meta_to_gz(ros: Any, data_size: int) -> tuple[Any, Take]:
    """Every field but ``data``; returns the gz Image and what it takes of the data.

    Raises:
        ConversionError: unknown encoding; ``step`` less than width * bytes per pixel; data
            shorter than height * step.
    """
    entry = ENCODINGS.get(ros.encoding)
    if entry is None:
        msg = (
            f"sensor_msgs/msg/Image encoding {ros.encoding!r} has no Gazebo pixel format; "
            f"supported: {', '.join(ENCODINGS)}"
        )
        raise ConversionError(msg)
    pixel_format, channels, depth = entry
    width, height, step = ros.width, ros.height, ros.step
    bytes_per_pixel = channels * depth
    row = width * bytes_per_pixel
    shape = f"{width}x{height} {ros.encoding}"
    if step < row:
        msg = (
            f"sensor_msgs/msg/Image step is {step}, less than width*bytes_per_pixel = "
            f"{width}*{bytes_per_pixel} = {row} for {shape}"
        )
        raise SizeMismatchError(msg)
    if data_size < height * step:
        msg = (
            f"sensor_msgs/msg/Image data has {data_size} bytes, fewer than height*step = "
            f"{height}*{step} = {height * step} for {shape}"
        )
        raise SizeMismatchError(msg)
    gz = GzImage()
    _IMAGE_SIZE.to_gz(ros, gz)
    gz.pixel_format_type = pixel_format
    gz.step = row
    return gz, (height * row if step == row or height <= 1 else Rows(height, row, step))


def image_to_gz(ros: Any) -> Any:
    data = memoryview(ros.data)
    gz, take = image_meta_to_gz(ros, len(data))
    pieces, _ = taken(data, take)
    gz.data = b"".join(pieces)
    return gz


def image_meta_to_ros(gz: Any, data_size: int) -> tuple[Any, int]:
    """Every field but ``data``; returns the ROS Image and how many data bytes it takes.

    Raises:
        ConversionError: unsupported pixel format; a row (width * bytes per pixel) wider than
            a uint32 ``step``; data shorter than height * that row.
    """
    entry = PIXEL_FORMATS.get(gz.pixel_format_type)
    if entry is None:
        value = gz.pixel_format_type
        name = _FORMAT_NAMES.get(value)
        spelled = f"{value} ({name})" if name else str(value)
        msg = (
            f"gz.msgs.Image pixel_format_type {spelled} has no ROS encoding; "
            f"supported: {_SUPPORTED_FORMATS}"
        )
        raise ConversionError(msg)
    encoding, bytes_per_pixel = entry
    width, height = gz.width, gz.height
    step = width * bytes_per_pixel
    shape = f"{width}x{height} {encoding}"
    if step > UINT32_MAX:
        msg = (
            f"gz.msgs.Image width*bytes_per_pixel = {width}*{bytes_per_pixel} = {step} for "
            f"{shape} does not fit the uint32 step of sensor_msgs/msg/Image"
        )
        raise SizeMismatchError(msg)
    if data_size < height * step:
        msg = (
            f"gz.msgs.Image data has {data_size} bytes, fewer than height*step = "
            f"{height}*{step} = {height * step} for {shape} (step = width*bytes_per_pixel; "
            "the gz step is ignored)"
        )
        raise SizeMismatchError(msg)
    ros = Image()
    _IMAGE_SIZE.to_ros(gz, ros)
    ros.encoding = encoding
    ros.is_bigendian = 0
    ros.step = step
    return ros, height * step


def image_to_ros(gz: Any) -> Any:
    data: bytes = gz.data
    ros, size = image_meta_to_ros(gz, len(data))
    ros.data = data if len(data) == size else data[:size]
    return ros


#: Image on the bulk path: gz ``data`` is field 5; ROS ``data`` is the last field.
IMAGE_BULK = BulkPath(
    gz_field=5,
    ros_layout=layout_until(Image, "data"),
    gz_meta_to_ros=image_meta_to_ros,
    ros_meta_to_gz=image_meta_to_gz,
)


def camera_info_to_gz(ros: Any) -> Any:
    """An unknown distortion model leaves gz ``model`` at 0 (PLUMB_BOB), as in C++."""
    gz = GzCameraInfo()
    _IMAGE_SIZE.to_gz(ros, gz)
    gz.distortion.SetInParent()
    gz.distortion.model = DISTORTION_MODELS.get(ros.distortion_model, 0)
    gz.distortion.k.extend(ros.d)
    gz.intrinsics.SetInParent()
    gz.intrinsics.k.extend(ros.k)
    gz.projection.SetInParent()
    gz.projection.p.extend(ros.p)
    gz.rectification_matrix.extend(ros.r)
    return gz


def _fixed(values: Any, size: int) -> list[float]:
    """The first ``size`` values, zero-padded to ``size``."""
    head = list(values[:size])
    return head + [0.0] * (size - len(head))


def camera_info_to_ros(gz: Any) -> Any:
    """An unknown gz distortion model leaves ``distortion_model`` empty, as in C++."""
    ros = CameraInfo()
    _IMAGE_SIZE.to_ros(gz, ros)
    if gz.HasField("distortion"):
        ros.distortion_model = _DISTORTION_NAMES.get(gz.distortion.model, "")
        ros.d = list(gz.distortion.k)
    if gz.HasField("intrinsics"):
        ros.k = _fixed(gz.intrinsics.k, 9)
    if gz.HasField("projection"):
        ros.p = _fixed(gz.projection.p, 12)
    ros.r = _fixed(gz.rectification_matrix, 9)
    return ros

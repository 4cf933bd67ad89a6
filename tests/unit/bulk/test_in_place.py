"""The bulk path's CDR built in the received frame (``bulk/path.py`` ``in_place``): the same
bytes as the joined copy, written only where the frame has room and only on success."""

from __future__ import annotations

from typing import Any

import pytest
from rclpy.serialization import deserialize_message
from sensor_msgs.msg import Image, PointCloud2

from ros_gz_bridge_py.bulk.path import gz_to_ros_cdr
from ros_gz_bridge_py.converters.registry import default_registry
from ros_gz_bridge_py.errors import ConversionError
from ros_gz_bridge_py.msgs import message_class

GzImage = message_class("gz.msgs.Image")
GzCloud = message_class("gz.msgs.PointCloudPacked")
IMAGE = default_registry().get("sensor_msgs/msg/Image", "gz.msgs.Image")
CLOUD = default_registry().get("sensor_msgs/msg/PointCloud2", "gz.msgs.PointCloudPacked")
RGB_INT8 = 3


def _header(msg: Any, entries: tuple[tuple[str, str], ...]) -> None:
    msg.header.stamp.sec = 1_700_000_000
    msg.header.stamp.nsec = 123_456_789
    for key, value in entries:
        entry = msg.header.data.add()
        entry.key = key
        entry.value.append(value)


def _camera_frame(width: int, height: int, *, header: bool = True, extra: int = 0) -> Any:
    """An rgb8 frame with a gz-sensors camera's header (stamp, seq, frame_id), or none."""
    frame = GzImage(width=width, height=height, step=width * 3, pixel_format_type=RGB_INT8)
    frame.data = bytes((i * 31 + 7) % 256 for i in range(width * height * 3 + extra))
    if header:
        _header(frame, (("seq", "41872"), ("frame_id", "robot::camera_link::camera")))
    return frame


def _same_cdr(built: memoryview, joined: bytes | memoryview, ros_class: type[Any]) -> None:
    """The two serialized messages are the same message, byte for byte but for CDR padding:
    rclpy's serializer leaves padding unwritten (whatever the heap held), so two serializations
    of one message may differ there (one run of the suite read 0x10 in one, 0xc5 in the other)."""
    assert len(built) == len(joined)
    assert deserialize_message(bytes(built), ros_class) == deserialize_message(
        bytes(joined), ros_class
    )


def _converted(pair: Any, gz: Any, payload: memoryview) -> bytes | memoryview:
    assert pair.bulk is not None
    return gz_to_ros_cdr(pair.bulk, type(gz), payload)


@pytest.mark.parametrize("extra", [0, 9])  # data as long as the image, and longer (truncated)
def test_a_camera_frame_is_built_in_place_with_the_joined_bytes(extra: int) -> None:
    gz = _camera_frame(16, 12, extra=extra)
    joined = _converted(IMAGE, gz, memoryview(gz.SerializeToString()))
    assert isinstance(joined, bytes)  # a read-only payload: the copy
    frame = bytearray(gz.SerializeToString())
    built = _converted(IMAGE, gz, memoryview(frame))
    assert isinstance(built, memoryview)
    assert built.obj is frame  # a view of the frame: the data not copied
    _same_cdr(built, joined, Image)
    assert deserialize_message(joined, Image) == IMAGE.to_ros(gz)


def test_a_frame_without_room_before_its_data_is_copied_and_left_alone() -> None:
    gz = _camera_frame(16, 12, header=False)  # 9 bytes before the data; the CDR needs 48
    frame = bytearray(gz.SerializeToString())
    built = _converted(IMAGE, gz, memoryview(frame))
    assert isinstance(built, bytes)
    assert frame == gz.SerializeToString()
    assert deserialize_message(built, Image) == IMAGE.to_ros(gz)


def test_a_refused_frame_is_left_alone() -> None:
    gz = _camera_frame(16, 12)
    gz.data = gz.data[:-1]  # one byte short of height*step
    frame = bytearray(gz.SerializeToString())
    with pytest.raises(ConversionError, match="fewer than height\\*step"):
        _converted(IMAGE, gz, memoryview(frame))
    assert frame == gz.SerializeToString()


def test_a_cloud_is_built_in_place_with_its_field_after_the_data() -> None:
    """PointCloud2's is_dense follows data in CDR: written over the records after it."""
    gz = GzCloud(height=1, width=4, point_step=4, row_step=16, is_bigendian=False, is_dense=True)
    gz.field.add(name="x", offset=0, count=1, datatype=6)  # FLOAT32
    gz.data = bytes(range(16))
    _header(gz, (("seq", "123456789"), ("frame_id", "lidar"), ("sensor", "front_lidar_long")))
    joined = _converted(CLOUD, gz, memoryview(gz.SerializeToString()))
    frame = bytearray(gz.SerializeToString())
    built = _converted(CLOUD, gz, memoryview(frame))
    assert isinstance(built, memoryview)
    assert built.obj is frame
    _same_cdr(built, joined, PointCloud2)
    got = deserialize_message(joined, PointCloud2)
    assert got == CLOUD.to_ros(gz)
    assert (got.is_dense, bytes(got.data)) == (True, bytes(range(16)))

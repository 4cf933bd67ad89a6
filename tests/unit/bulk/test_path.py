"""The bulk path gives exactly what the object path gives, both ways, errors included."""

from __future__ import annotations

from typing import Any

import pytest
from rclpy.serialization import deserialize_message, serialize_message
from sensor_msgs.msg import Image, PointCloud2, PointField

from ros_gz_bridge_py.bulk.path import gz_to_ros_cdr, ros_cdr_to_gz
from ros_gz_bridge_py.converters.registry import default_registry
from ros_gz_bridge_py.errors import ConversionError
from ros_gz_bridge_py.msgs import message_class

GzImage = message_class("gz.msgs.Image")
GzCloud = message_class("gz.msgs.PointCloudPacked")
IMAGE = default_registry().get("sensor_msgs/msg/Image", "gz.msgs.Image")
CLOUD = default_registry().get("sensor_msgs/msg/PointCloud2", "gz.msgs.PointCloudPacked")


def _gz_image(data_size: int, *, fmt: int = 8, width: int = 5, height: int = 3) -> Any:
    image = GzImage(width=width, height=height, step=999, pixel_format_type=fmt)
    image.data = bytes((i * 13 + 1) % 251 for i in range(data_size))
    image.header.stamp.sec = 1234
    image.header.stamp.nsec = 5678
    for key, value in (("frame_id", "first"), ("seq", "9"), ("frame_id", "robot::camera")):
        entry = image.header.data.add()
        entry.key = key
        entry.value.append(value)
    return image


def _gz_cloud() -> Any:
    cloud = GzCloud(height=2, width=3, is_bigendian=True, point_step=2, row_step=6, is_dense=True)
    cloud.data = bytes(range(100, 112))
    cloud.field.add(name="x", offset=0, datatype=1, count=1)
    cloud.field.add(name="y", offset=1, datatype=0, count=2)
    cloud.header.stamp.sec = 3
    return cloud


def _ros_image(data_size: int, encoding: str = "mono16") -> Image:
    msg = Image(height=2, width=3, encoding=encoding, is_bigendian=1, step=77)
    msg.data = bytes((i * 7 + 2) % 256 for i in range(data_size))
    msg.header.stamp.sec = -3
    msg.header.stamp.nanosec = 999_999_999
    msg.header.frame_id = "optical"
    return msg


def _ros_cloud() -> PointCloud2:
    msg = PointCloud2(height=1, width=4, point_step=3, row_step=12, is_dense=False)
    msg.fields = [
        PointField(name="z", offset=0, datatype=PointField.FLOAT64, count=1),
        PointField(name="odd", offset=2, datatype=99, count=3),
    ]
    msg.data = bytes(range(12, 0, -1))
    msg.header.frame_id = "lidar"
    return msg


@pytest.mark.parametrize("extra", [0, 7])  # exact size, and longer data truncated
def test_image_gazebo_to_ros_matches_the_object_path(extra: int) -> None:
    gz = _gz_image(5 * 3 * 3 + extra)
    assert IMAGE.bulk is not None
    cdr = gz_to_ros_cdr(IMAGE.bulk, GzImage, memoryview(gz.SerializeToString()))
    expected = IMAGE.to_ros(gz)
    assert deserialize_message(cdr, Image) == expected
    assert expected.header.frame_id == "robot/camera"
    assert len(expected.data) == 45


def test_cloud_gazebo_to_ros_matches_the_object_path() -> None:
    gz = _gz_cloud()
    assert CLOUD.bulk is not None
    cdr = gz_to_ros_cdr(CLOUD.bulk, GzCloud, memoryview(gz.SerializeToString()))
    assert deserialize_message(cdr, PointCloud2) == CLOUD.to_ros(gz)
    assert deserialize_message(cdr, PointCloud2).is_dense


def test_finish_edits_the_header_before_serialization() -> None:
    def finish(msg: Any) -> None:
        msg.header.frame_id = "override"
        msg.header.stamp.sec = 77

    assert IMAGE.bulk is not None
    payload = _gz_image(45).SerializeToString()
    msg = deserialize_message(
        gz_to_ros_cdr(IMAGE.bulk, GzImage, memoryview(payload), finish), Image
    )
    assert (msg.header.frame_id, msg.header.stamp.sec, msg.header.stamp.nanosec) == (
        "override",
        77,
        5678,
    )


@pytest.mark.parametrize(
    ("gz", "text"), [(_gz_image(44), "fewer than"), (_gz_image(45, fmt=99), "99")]
)
def test_image_gazebo_to_ros_errors_match_the_object_path(gz: Any, text: str) -> None:
    with pytest.raises(ConversionError, match=text) as object_error:
        IMAGE.to_ros(gz)
    assert IMAGE.bulk is not None
    with pytest.raises(ConversionError) as bulk_error:
        gz_to_ros_cdr(IMAGE.bulk, GzImage, memoryview(gz.SerializeToString()))
    assert str(bulk_error.value) == str(object_error.value)


def test_undecodable_small_fields_are_a_conversion_error() -> None:
    assert IMAGE.bulk is not None
    payload = b"\x0a\x02\xff\xff" + b"\x2a\x01x"  # header: garbage; data: "x"
    with pytest.raises(ConversionError, match="not a valid message"):
        gz_to_ros_cdr(IMAGE.bulk, GzImage, memoryview(payload))


@pytest.mark.parametrize("extra", [0, 5])
def test_image_ros_to_gazebo_matches_the_object_path(extra: int) -> None:
    ros = _ros_image(2 * 3 * 2 + extra)
    assert IMAGE.bulk is not None
    payload = ros_cdr_to_gz(IMAGE.bulk, Image, serialize_message(ros))
    assert payload is not None
    expected = IMAGE.to_gz(ros)
    assert GzImage.FromString(payload) == expected
    assert len(expected.data) == 12


def test_cloud_ros_to_gazebo_matches_the_object_path() -> None:
    ros = _ros_cloud()
    assert CLOUD.bulk is not None
    payload = ros_cdr_to_gz(CLOUD.bulk, PointCloud2, serialize_message(ros))
    assert payload is not None
    assert GzCloud.FromString(payload) == CLOUD.to_gz(ros)


@pytest.mark.parametrize(
    ("ros", "text"), [(_ros_image(11), "fewer than"), (_ros_image(12, "yuv"), "yuv")]
)
def test_image_ros_to_gazebo_errors_match_the_object_path(ros: Image, text: str) -> None:
    with pytest.raises(ConversionError, match=text) as object_error:
        IMAGE.to_gz(ros)
    assert IMAGE.bulk is not None
    with pytest.raises(ConversionError) as bulk_error:
        ros_cdr_to_gz(IMAGE.bulk, Image, serialize_message(ros))
    assert str(bulk_error.value) == str(object_error.value)


def test_other_encapsulation_returns_none_for_the_object_path() -> None:
    cdr = bytearray(serialize_message(_ros_image(12)))
    cdr[1] = 0x07
    assert IMAGE.bulk is not None
    assert ros_cdr_to_gz(IMAGE.bulk, Image, bytes(cdr)) is None


class _CountedHash(bytes):
    """bytes whose hashing is counted: a memoryview hashes its exporter whole."""

    hashed = 0

    def __hash__(self) -> int:
        type(self).hashed += 1
        return super().__hash__()


def test_neither_direction_hashes_the_message() -> None:
    assert IMAGE.bulk is not None
    _CountedHash.hashed = 0
    hash(memoryview(_CountedHash(b"\x00\x01\x02\x03"))[:2])  # the trap works
    assert _CountedHash.hashed == 1
    _CountedHash.hashed = 0
    ros = _ros_image(12)
    payload = ros_cdr_to_gz(IMAGE.bulk, Image, _CountedHash(serialize_message(ros)))
    assert payload is not None
    assert GzImage.FromString(payload) == IMAGE.to_gz(ros)
    gz = _gz_image(45)
    cdr = gz_to_ros_cdr(IMAGE.bulk, GzImage, memoryview(_CountedHash(gz.SerializeToString())))
    assert deserialize_message(cdr, Image) == IMAGE.to_ros(gz)
    assert _CountedHash.hashed == 0

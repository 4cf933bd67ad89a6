"""Finding the uint8[] field of a serialized ROS message, against rclpy's own serializer."""

from __future__ import annotations

import pytest
from rclpy.serialization import serialize_message
from sensor_msgs.msg import CompressedImage, Image, PointCloud2, PointField

from ros_gz_bridge_py.bulk.cdr import Sequence, layout_until, locate_bulk
from ros_gz_bridge_py.converters.sensor_msgs_image import IMAGE_BULK
from ros_gz_bridge_py.converters.sensor_msgs_scan import POINT_CLOUD2_BULK
from ros_gz_bridge_py.errors import ConversionError


def _image(frame_id: str, encoding: str, data: bytes) -> Image:
    msg = Image(height=1, width=len(data), encoding=encoding, step=len(data), data=data)
    msg.header.frame_id = frame_id
    return msg


@pytest.mark.parametrize("frame_id", ["", "a", "ab", "abc", "abcd", "camera/optical_frame"])
@pytest.mark.parametrize("encoding", ["", "rgb8", "mono16", "32FC1"])
def test_image_data_found_whatever_the_string_padding(frame_id: str, encoding: str) -> None:
    data = b"\x01\x02\x03\x04\x05"
    cdr = serialize_message(_image(frame_id, encoding, data))
    where = locate_bulk(memoryview(cdr), IMAGE_BULK.ros_layout)
    assert where is not None
    assert where.little_endian
    assert cdr[where.start : where.end] == data
    assert int.from_bytes(cdr[where.length_at : where.length_at + 4], "little") == len(data)
    assert where.end == len(cdr)


@pytest.mark.parametrize("names", [[], ["x"], ["x", "yy", "intensity"]])
def test_point_cloud_data_found_after_the_fields(names: list[str]) -> None:
    msg = PointCloud2(height=1, width=2, point_step=4, row_step=8, is_dense=True)
    msg.fields = [
        PointField(name=n, offset=i, datatype=PointField.UINT8, count=1)
        for i, n in enumerate(names)
    ]
    msg.data = b"ABCDEFGH"
    cdr = serialize_message(msg)
    where = locate_bulk(memoryview(cdr), POINT_CLOUD2_BULK.ros_layout)
    assert where is not None
    assert cdr[where.start : where.end] == b"ABCDEFGH"
    assert cdr[where.end :] == b"\x01"  # is_dense, the only field after data


def test_big_endian_encapsulation() -> None:
    # CompressedImage: header (sec, nanosec, frame_id ""), format "", then data; big endian.
    header = b"\x00\x00\x00\x01" + b"\x00\x00\x00\x02" + b"\x00\x00\x00\x01\x00" + b"\x00" * 3
    body = header + b"\x00\x00\x00\x01\x00" + b"\x00" * 3
    cdr = b"\x00\x00\x00\x00" + body + b"\x00\x00\x00\x03xyz"
    where = locate_bulk(memoryview(cdr), layout_until(CompressedImage, "data"))
    assert where is not None
    assert not where.little_endian
    assert cdr[where.start : where.end] == b"xyz"


def test_other_encapsulations_are_left_to_rclpy() -> None:
    assert (
        locate_bulk(memoryview(b"\x00\x07\x00\x00" + b"\x00" * 16), IMAGE_BULK.ros_layout) is None
    )
    assert locate_bulk(memoryview(b"\x00"), IMAGE_BULK.ros_layout) is None


def test_truncated_message_is_a_conversion_error() -> None:
    cdr = serialize_message(_image("cam", "rgb8", b"123456"))
    with pytest.raises(ConversionError, match="ends inside a field"):
        locate_bulk(memoryview(cdr[:-2]), IMAGE_BULK.ros_layout)


def test_layout_without_bulk_is_a_programming_error() -> None:
    with pytest.raises(ValueError, match="no 'bulk'"):
        locate_bulk(memoryview(b"\x00\x01\x00\x00" + b"\x00" * 8), (Sequence(()), "u32"))


def test_layouts_derived_from_the_type_description() -> None:
    header = ("u32", "u32", "str")
    assert IMAGE_BULK.ros_layout == (*header, "u32", "u32", "str", "u8", "u32", "bulk")
    point_field = Sequence(("str", "u32", "u8", "u32"))
    assert POINT_CLOUD2_BULK.ros_layout == (
        *header, "u32", "u32", point_field, "u8", "u32", "u32", "bulk",
    )  # fmt: skip


def test_derived_layouts_walk_other_widths() -> None:
    from nav_msgs.msg import OccupancyGrid  # noqa: PLC0415

    # OccupancyGrid: header, MapMetaData (Time, float32, 2 x uint32, Pose of doubles), int8[].
    layout = layout_until(OccupancyGrid, "data")
    assert "u64" in layout
    msg = OccupancyGrid()
    msg.header.frame_id = "map"
    msg.info.width = 3
    msg.info.origin.position.x = 1.5
    msg.data = [1, -2, 3]
    cdr = serialize_message(msg)
    where = locate_bulk(memoryview(cdr), layout)
    assert where is not None
    assert cdr[where.start : where.end] == b"\x01\xfe\x03"


@pytest.mark.parametrize(
    ("field", "reason"),
    [("nope", "no field"), ("encoding", "not a sequence"), ("height", "not a sequence")],
)
def test_layout_until_refuses_what_it_cannot_splice(field: str, reason: str) -> None:
    with pytest.raises(ValueError, match=reason):
        layout_until(Image, field)


def test_layout_until_refuses_wide_fields_after_the_bulk() -> None:
    from rosidl_parser.definition import BasicType, UnboundedSequence  # noqa: PLC0415

    class Spliced:
        """A message type whose uint32 after the data would move with the data's length."""

        SLOT_TYPES = (UnboundedSequence(BasicType("uint8")), BasicType("uint32"))

        @staticmethod
        def get_fields_and_field_types() -> dict[str, str]:
            return {"data": "sequence<uint8>", "count": "uint32"}

    with pytest.raises(ValueError, match="count after data is not one byte wide"):
        layout_until(Spliced, "data")

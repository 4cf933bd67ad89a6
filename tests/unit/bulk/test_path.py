"""The bulk path gives exactly what the object path gives, both ways, errors included.

ROS -> Gazebo has two object paths: the converter on rclpy's message
(``ROS_GZ_BRIDGE_LIGHT_READ=off``) and on the ``ros_cdr`` tree of the same CDR (the default
once ``ROS_GZ_BRIDGE_BULK_PATH=off``); every outcome is compared across all of them.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import pytest
from rclpy.serialization import deserialize_message, serialize_message
from sensor_msgs.msg import Image, PointCloud2, PointField

from ros_gz_bridge_py.bulk.path import Rows, gz_to_ros_cdr, ros_cdr_to_gz, taken
from ros_gz_bridge_py.converters.registry import Pair, default_registry
from ros_gz_bridge_py.errors import ConversionError
from ros_gz_bridge_py.msgs import message_class
from ros_gz_bridge_py.ros import light_reader

GzImage = message_class("gz.msgs.Image")
GzCloud = message_class("gz.msgs.PointCloudPacked")
IMAGE = default_registry().get("sensor_msgs/msg/Image", "gz.msgs.Image")
CLOUD = default_registry().get("sensor_msgs/msg/PointCloud2", "gz.msgs.PointCloudPacked")
U32 = 4_294_967_295
#: ROS PointField datatype -> gz Field.DataType; an unknown ROS value meets an unknown gz one.
_GZ_DATATYPES = {ros: ros - 1 for ros in range(1, 9)}
_GZ_UNKNOWN = 42

Outcome = tuple[str, Any]


def _outcome(convert: Callable[[], Any]) -> Outcome:
    try:
        return "ok", convert()
    except ConversionError as err:
        return "error", str(err)


def ros_to_gz_outcomes(pair: Pair, ros: Any) -> dict[str, Outcome]:
    """The outcome of each ROS -> Gazebo path for ``ros``: a gz message or an error text."""
    assert pair.bulk is not None
    bulk = pair.bulk
    gz_class = message_class(pair.gz_type)
    cdr = serialize_message(ros)
    tree = light_reader.read(cdr, pair.ros_class)

    def on_bulk_path() -> Any:
        payload = ros_cdr_to_gz(bulk, pair.ros_class, cdr)
        assert payload is not None
        return gz_class.FromString(payload)

    return {
        "bulk": _outcome(on_bulk_path),
        "rclpy object": _outcome(lambda: pair.to_gz(ros)),
        "light tree": _outcome(lambda: pair.to_gz(tree)),
    }


def gz_to_ros_outcomes(pair: Pair, gz: Any) -> dict[str, Outcome]:
    """The outcome of each Gazebo -> ROS path for ``gz``: a ROS message or an error text."""
    assert pair.bulk is not None
    bulk = pair.bulk
    payload = memoryview(gz.SerializeToString())

    def on_bulk_path() -> Any:
        return deserialize_message(gz_to_ros_cdr(bulk, type(gz), payload), pair.ros_class)

    def on_bulk_path_own_frame() -> Any:  # writable, as a received frame: built in place
        own = memoryview(bytearray(payload))
        return deserialize_message(bytes(gz_to_ros_cdr(bulk, type(gz), own)), pair.ros_class)

    return {
        "bulk": _outcome(on_bulk_path),
        "bulk, own frame": _outcome(on_bulk_path_own_frame),
        "object": _outcome(lambda: pair.to_ros(gz)),
    }


def assert_all(outcomes: dict[str, Outcome], expected: Outcome) -> None:
    for path, outcome in outcomes.items():
        assert outcome == expected, path


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


def _ros_image(
    data_size: int,
    encoding: str = "mono16",
    *,
    step: int = 77,
    width: int = 3,
    height: int = 2,
) -> Image:
    msg = Image(height=height, width=width, encoding=encoding, is_bigendian=1, step=step)
    msg.data = bytes((i * 7 + 2) % 256 for i in range(data_size))
    msg.header.stamp.sec = -3
    msg.header.stamp.nanosec = 999_999_999
    msg.header.frame_id = "optical"
    return msg


#: A field as (name, offset, count, ROS datatype).
Field = tuple[str, int, int, int]


def _clouds(  # noqa: PLR0917 - every size is a test dimension
    height: int,
    width: int,
    point_step: int,
    row_step: int,
    fields: list[Field],
    data_size: int,
) -> tuple[PointCloud2, Any]:
    """The same cloud as a ROS message and as a gz message."""
    data = bytes((i * 29 + 5) % 256 for i in range(data_size))
    sizes = {"height": height, "width": width, "point_step": point_step, "row_step": row_step}
    ros = PointCloud2(**sizes, is_bigendian=True, is_dense=True, data=data)
    ros.fields = [
        PointField(name=name, offset=offset, count=count, datatype=datatype)
        for name, offset, count, datatype in fields
    ]
    ros.header.stamp.sec = 3
    ros.header.frame_id = "lidar"
    gz = GzCloud(**sizes, is_bigendian=True, is_dense=True, data=data)
    for name, offset, count, datatype in fields:
        gz_datatype = _GZ_DATATYPES.get(datatype, _GZ_UNKNOWN)
        gz.field.add(name=name, offset=offset, count=count, datatype=gz_datatype)
    gz.header.stamp.sec = 3
    entry = gz.header.data.add()
    entry.key = "frame_id"
    entry.value.append("lidar")
    return ros, gz


# --- Image -------------------------------------------------------------------------------


@pytest.mark.parametrize("extra", [0, 7])  # exact size, and longer data truncated
def test_image_gazebo_to_ros_matches_the_object_path(extra: int) -> None:
    gz = _gz_image(5 * 3 * 3 + extra)
    expected = IMAGE.to_ros(gz)
    assert_all(gz_to_ros_outcomes(IMAGE, gz), ("ok", expected))
    assert expected.header.frame_id == "robot/camera"
    assert (expected.step, len(expected.data)) == (15, 45)
    assert bytes(expected.data) == gz.data[:45]


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
    ("gz", "text"),
    [
        (
            _gz_image(45, fmt=99),
            "gz.msgs.Image pixel_format_type 99 has no ROS encoding; supported: L_INT8, "
            "L_INT16, RGB_INT8, RGBA_INT8, BGRA_INT8, RGB_INT16, BGR_INT8, BGR_INT16, R_FLOAT32",
        ),
        (
            _gz_image(44),
            "gz.msgs.Image data has 44 bytes, fewer than height*step = 3*15 = 45 for 5x3 bgr8 "
            "(step = width*bytes_per_pixel; the gz step is ignored)",
        ),
        (
            _gz_image(0, fmt=3, width=U32, height=0),
            "gz.msgs.Image width*bytes_per_pixel = 4294967295*3 = 12884901885 for "
            "4294967295x0 rgb8 does not fit the uint32 step of sensor_msgs/msg/Image",
        ),
        (
            _gz_image(0, fmt=3, width=U32 // 3 + 1, height=0),
            "gz.msgs.Image width*bytes_per_pixel = 1431655766*3 = 4294967298 for "
            "1431655766x0 rgb8 does not fit the uint32 step of sensor_msgs/msg/Image",
        ),
        (
            _gz_image(16, fmt=3, width=U32 // 3, height=1),
            "gz.msgs.Image data has 16 bytes, fewer than height*step = 1*4294967295 = "
            "4294967295 for 1431655765x1 rgb8 (step = width*bytes_per_pixel; the gz step "
            "is ignored)",
        ),
        (
            _gz_image(16, fmt=1, width=1, height=U32),
            "gz.msgs.Image data has 16 bytes, fewer than height*step = 4294967295*1 = "
            "4294967295 for 1x4294967295 mono8 (step = width*bytes_per_pixel; the gz step "
            "is ignored)",
        ),
    ],
)
def test_image_gazebo_to_ros_errors_match_the_object_path(gz: Any, text: str) -> None:
    assert_all(gz_to_ros_outcomes(IMAGE, gz), ("error", text))


def test_image_gazebo_to_ros_row_at_the_uint32_limit_converts() -> None:
    gz = _gz_image(0, fmt=3, width=U32 // 3, height=0)
    expected = IMAGE.to_ros(gz)
    assert_all(gz_to_ros_outcomes(IMAGE, gz), ("ok", expected))
    assert (expected.step, len(expected.data)) == (U32, 0)


def test_undecodable_small_fields_are_a_conversion_error() -> None:
    assert IMAGE.bulk is not None
    payload = b"\x0a\x02\xff\xff" + b"\x2a\x01x"  # header: garbage; data: "x"
    with pytest.raises(ConversionError, match="not a valid message"):
        gz_to_ros_cdr(IMAGE.bulk, GzImage, memoryview(payload))


@pytest.mark.parametrize("extra", [0, 5])  # exact size, and longer data truncated
def test_image_ros_to_gazebo_matches_the_object_path(extra: int) -> None:
    ros = _ros_image(2 * 6 + extra, step=6)
    expected = IMAGE.to_gz(ros)
    assert_all(ros_to_gz_outcomes(IMAGE, ros), ("ok", expected))
    assert (expected.step, expected.data) == (6, bytes(ros.data)[:12])


@pytest.mark.parametrize("extra", [0, 5])
def test_image_ros_to_gazebo_leaves_the_row_padding_out(extra: int) -> None:
    ros = _ros_image(2 * 77 + extra, step=77)
    expected = IMAGE.to_gz(ros)
    assert_all(ros_to_gz_outcomes(IMAGE, ros), ("ok", expected))
    data = bytes(ros.data)
    assert (expected.step, expected.data) == (6, data[0:6] + data[77:83])


def test_image_ros_to_gazebo_single_padded_row() -> None:
    ros = _ros_image(9, "rgb8", step=9, width=2, height=1)
    expected = IMAGE.to_gz(ros)
    assert_all(ros_to_gz_outcomes(IMAGE, ros), ("ok", expected))
    assert (expected.step, expected.data) == (6, bytes(ros.data)[:6])


@pytest.mark.parametrize(
    ("ros", "text"),
    [
        (
            _ros_image(154, "yuv"),
            "sensor_msgs/msg/Image encoding 'yuv' has no Gazebo pixel format; supported: "
            "mono8, mono16, rgb8, rgba8, bgra8, rgb16, bgr8, bgr16, 32FC1",
        ),
        (
            _ros_image(12, step=5),
            "sensor_msgs/msg/Image step is 5, less than width*bytes_per_pixel = 3*2 = 6 "
            "for 3x2 mono16",
        ),
        (
            _ros_image(0, step=0, height=0),
            "sensor_msgs/msg/Image step is 0, less than width*bytes_per_pixel = 3*2 = 6 "
            "for 3x0 mono16",
        ),
        (
            _ros_image(153, step=77),
            "sensor_msgs/msg/Image data has 153 bytes, fewer than height*step = 2*77 = 154 "
            "for 3x2 mono16",
        ),
        (
            _ros_image(11, step=6),
            "sensor_msgs/msg/Image data has 11 bytes, fewer than height*step = 2*6 = 12 "
            "for 3x2 mono16",
        ),
        (
            _ros_image(16, "rgb8", step=U32, width=U32, height=1),
            "sensor_msgs/msg/Image step is 4294967295, less than width*bytes_per_pixel = "
            "4294967295*3 = 12884901885 for 4294967295x1 rgb8",
        ),
        (
            _ros_image(16, "mono8", step=U32, width=1, height=U32),
            "sensor_msgs/msg/Image data has 16 bytes, fewer than height*step = "
            "4294967295*4294967295 = 18446744065119617025 for 1x4294967295 mono8",
        ),
    ],
)
def test_image_ros_to_gazebo_errors_match_the_object_path(ros: Image, text: str) -> None:
    assert_all(ros_to_gz_outcomes(IMAGE, ros), ("error", text))


def test_other_encapsulation_returns_none_for_the_object_path() -> None:
    cdr = bytearray(serialize_message(_ros_image(154)))
    cdr[1] = 0x07
    assert IMAGE.bulk is not None
    assert ros_cdr_to_gz(IMAGE.bulk, Image, bytes(cdr)) is None


# --- PointCloud2 -----------------------------------------------------------------------------

XYZ: list[Field] = [("x", 0, 1, PointField.FLOAT32), ("y", 4, 1, PointField.FLOAT32)]
ODD: list[Field] = [
    ("z", 0, 1, PointField.FLOAT64),
    ("ring", 8, 2, PointField.UINT16),
    ("odd", 12, 3, 99),  # unknown: INT8 on the other side
    ("none", 15, 0, PointField.FLOAT64),  # no elements: ends where it starts
]


@pytest.mark.parametrize(
    "sizes",
    [
        pytest.param((2, 3, 15, 45, ODD, 90), id="exact"),
        pytest.param((2, 3, 15, 47, ODD, 94), id="row padding"),
        pytest.param((3, 2, 8, 16, XYZ, 48), id="xy"),
        pytest.param((0, 5, 8, 40, XYZ, 0), id="no rows"),
        pytest.param((1, 0, 8, 0, XYZ, 0), id="no points"),
        pytest.param((1, 1, 0, 0, [], 0), id="no fields"),
    ],
)
def test_cloud_matches_the_object_path_both_ways(
    sizes: tuple[int, int, int, int, list[Field], int],
) -> None:
    ros, gz = _clouds(*sizes)
    to_gz = CLOUD.to_gz(ros)
    to_ros = CLOUD.to_ros(gz)
    assert_all(ros_to_gz_outcomes(CLOUD, ros), ("ok", to_gz))
    assert_all(gz_to_ros_outcomes(CLOUD, gz), ("ok", to_ros))
    assert to_gz.data == bytes(ros.data) == bytes(to_ros.data)
    unknown_as_int8 = [f.datatype for f in to_ros.fields]
    assert [f.datatype for f in to_gz.field] == [_GZ_DATATYPES.get(d, 0) for _, _, _, d in sizes[4]]
    assert unknown_as_int8 == [d if d in _GZ_DATATYPES else 1 for _, _, _, d in sizes[4]]


#: (sizes, what is wrong) with ``{fields}`` for the list's name on each side and ``{odd}`` for
#: the unknown datatype as the sender wrote it.
CLOUD_ERRORS = [
    pytest.param(
        (1, U32, 16, 16, [("x", 0, 1, PointField.FLOAT32)], 16),
        "row_step is 16, less than width*point_step = 4294967295*16 = 68719476720",
        id="issue 14: width 4294967295 with 16 bytes",
    ),
    pytest.param(
        (0, U32, 16, U32, [("x", 0, 1, PointField.FLOAT32)], 0),
        "row_step is 4294967295, less than width*point_step = 4294967295*16 = 68719476720",
        id="row_step at the uint32 limit, no rows",
    ),
    pytest.param(
        (2, 3, 15, 45, ODD, 91),
        "data has 91 bytes, not height*row_step = 2*45 = 90",
        id="longer data",
    ),
    pytest.param(
        (2, 3, 15, 45, ODD, 89),
        "data has 89 bytes, not height*row_step = 2*45 = 90",
        id="shorter data",
    ),
    pytest.param(
        (U32, 1, 1, U32, [], 16),
        "data has 16 bytes, not height*row_step = 4294967295*4294967295 = 18446744065119617025",
        id="height*row_step past 2**64",
    ),
    pytest.param(
        (1, 2, 14, 28, ODD[:3], 28),
        "{fields}[2] 'odd' (3 x {odd}) ends at offset+count*size = 12+3*1 = 15, past "
        "point_step = 14",
        id="unknown datatype past point_step",
    ),
    pytest.param(
        (1, 2, 8, 16, [("x", 0, 1, PointField.FLOAT32), ("t", 4, 1, PointField.FLOAT64)], 16),
        "{fields}[1] 't' (1 x FLOAT64) ends at offset+count*size = 4+1*8 = 12, past point_step = 8",
        id="field past point_step",
    ),
    pytest.param(
        (0, 1, U32, U32, [("big", U32, U32, PointField.FLOAT64)], 0),
        "{fields}[0] 'big' (4294967295 x FLOAT64) ends at offset+count*size = "
        "4294967295+4294967295*8 = 38654705655, past point_step = 4294967295",
        id="field count past 2**32",
    ),
    pytest.param(
        (2, U32, 4, 8, [("x", 2, 1, PointField.FLOAT32), ("y", 9, 0, PointField.INT8)], 3),
        "{fields}[0] 'x' (1 x FLOAT32) ends at offset+count*size = 2+1*4 = 6, past "
        "point_step = 4; {fields}[1] 'y' (0 x INT8) ends at offset+count*size = 9+0*1 = 9, "
        "past point_step = 4; row_step is 8, less than width*point_step = 4294967295*4 = "
        "17179869180; data has 3 bytes, not height*row_step = 2*8 = 16",
        id="everything wrong at once",
    ),
]


@pytest.mark.parametrize(("sizes", "problems"), CLOUD_ERRORS)
def test_cloud_errors_match_the_object_path_both_ways(
    sizes: tuple[int, int, int, int, list[Field], int], problems: str
) -> None:
    ros, gz = _clouds(*sizes)
    to_gz = problems.format(fields="fields", odd="datatype 99 taken as INT8")
    to_ros = problems.format(fields="field", odd=f"datatype {_GZ_UNKNOWN} taken as INT8")
    assert_all(
        ros_to_gz_outcomes(CLOUD, ros),
        ("error", f"sensor_msgs/msg/PointCloud2 sizes do not match its data: {to_gz}"),
    )
    assert_all(
        gz_to_ros_outcomes(CLOUD, gz),
        ("error", f"gz.msgs.PointCloudPacked sizes do not match its data: {to_ros}"),
    )


def test_cloud_data_first_in_the_gazebo_payload() -> None:
    _, gz = _clouds(2, 3, 15, 45, ODD, 90)
    rest = GzCloud()
    rest.CopyFrom(gz)
    rest.ClearField("data")
    payload = bytes([8 << 3 | 2, 90]) + gz.data + rest.SerializeToString()
    assert CLOUD.bulk is not None
    cdr = gz_to_ros_cdr(CLOUD.bulk, GzCloud, memoryview(payload))
    assert deserialize_message(cdr, PointCloud2) == CLOUD.to_ros(gz)


# --- What an output takes ------------------------------------------------------------------


def test_taken_selects_a_prefix_or_rows_without_their_padding() -> None:
    bulk = memoryview(b"ab_cd_ef")
    pieces, size = taken(bulk, 3)
    assert ([bytes(p) for p in pieces], size) == ([b"ab_"], 3)
    pieces, size = taken(bulk, Rows(count=3, size=2, stride=3))
    assert ([bytes(p) for p in pieces], size) == ([b"ab", b"cd", b"ef"], 6)


@pytest.mark.parametrize("take", [9, Rows(count=3, size=3, stride=3), Rows(4, 1, 3)])
def test_taken_refuses_to_run_past_the_bulk_field(take: int | Rows) -> None:
    with pytest.raises(ValueError, match="past the 8 of the bulk field"):
        taken(memoryview(b"ab_cd_ef"), take)


# --- Costs -------------------------------------------------------------------------------


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
    for ros in (_ros_image(12, step=6), _ros_image(154, step=77)):
        payload = ros_cdr_to_gz(IMAGE.bulk, Image, _CountedHash(serialize_message(ros)))
        assert payload is not None
        assert GzImage.FromString(payload) == IMAGE.to_gz(ros)
    gz = _gz_image(45)
    cdr = gz_to_ros_cdr(IMAGE.bulk, GzImage, memoryview(_CountedHash(gz.SerializeToString())))
    assert deserialize_message(cdr, Image) == IMAGE.to_ros(gz)
    assert _CountedHash.hashed == 0

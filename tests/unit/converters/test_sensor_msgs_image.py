"""sensor_msgs Image and CameraInfo (docs/conversions-per-package.md §3.5)."""

from __future__ import annotations

import pytest
from sensor_msgs.msg import CameraInfo, Image

from ros_gz_bridge_py.converters.sensor_msgs_image import (
    ENCODINGS,
    camera_info_to_gz,
    camera_info_to_ros,
    image_to_gz,
    image_to_ros,
)
from ros_gz_bridge_py.errors import ConversionError
from ros_gz_bridge_py.msgs import message_class

GzImage = message_class("gz.msgs.Image")
GzCameraInfo = message_class("gz.msgs.CameraInfo")


def test_upstream_fixture_round_trips() -> None:
    ros = Image(width=320, height=240, encoding="rgb8", step=960, data=b"1" * 230400)
    ros.header.frame_id = "camera"
    gz = image_to_gz(ros)
    assert (gz.pixel_format_type, gz.step, len(gz.data)) == (3, 960, 230400)
    assert image_to_ros(gz) == ros


@pytest.mark.parametrize("encoding", sorted(ENCODINGS))
def test_every_encoding_round_trips(encoding: str) -> None:
    _, channels, depth = ENCODINGS[encoding]
    step = 3 * channels * depth
    ros = Image(width=3, height=2, encoding=encoding, step=step, data=bytes(range(step * 2)))
    assert image_to_ros(image_to_gz(ros)) == ros


def test_ros_row_padding_is_left_out_row_by_row_and_step_recomputed() -> None:
    ros = Image(width=2, height=3, encoding="mono8", step=5, data=b"ab...cd,,,ef;;;tail")
    gz = image_to_gz(ros)
    assert (gz.step, gz.data) == (2, b"abcdef")
    back = image_to_ros(gz)
    assert (back.step, bytes(back.data)) == (2, b"abcdef")


def test_unknown_encoding_and_short_data_are_rejected() -> None:
    with pytest.raises(ConversionError, match="yuv422"):
        image_to_gz(Image(width=1, height=1, encoding="yuv422", data=b"ab"))
    with pytest.raises(
        ConversionError, match=r"data has 3 bytes, fewer than height\*step = 2\*2 = 4 for 2x2"
    ):
        image_to_gz(Image(width=2, height=2, encoding="mono8", step=2, data=b"abc"))
    with pytest.raises(ConversionError, match=r"pixel_format_type 7 \(RGB_INT32\) has no ROS"):
        image_to_ros(GzImage(width=1, height=1, pixel_format_type=7))
    # by name, as the ROS -> Gazebo direction lists encodings (it said "15" alone)
    with pytest.raises(ConversionError, match=r"15 \(BAYER_RGGB8\) .*; supported: L_INT8, "):
        image_to_ros(GzImage(width=1, height=1, pixel_format_type=15))


def test_ros_step_shorter_than_a_row_is_rejected() -> None:
    """Rows that overlap: the step the ROS publisher wrote contradicts width and encoding."""
    ros = Image(width=2, height=2, encoding="rgb16", step=11, data=bytes(24))
    with pytest.raises(
        ConversionError, match=r"step is 11, less than width\*bytes_per_pixel = 2\*6 = 12"
    ):
        image_to_gz(ros)


def test_long_gz_data_is_truncated_and_short_data_rejected() -> None:
    long_gz = GzImage(width=2, height=1, pixel_format_type=1, data=b"abcdef")
    assert bytes(image_to_ros(long_gz).data) == b"ab"
    long_ros = Image(width=2, height=1, encoding="mono8", step=2, data=b"abcdef")
    assert image_to_gz(long_ros).data == b"ab"
    short_gz = GzImage(width=2, height=2, pixel_format_type=1, data=b"abc")
    with pytest.raises(ConversionError, match=r"3 bytes, fewer than height\*step = 2\*2 = 4"):
        image_to_ros(short_gz)


def test_camera_info_upstream_fixture_round_trips() -> None:
    ros = CameraInfo(
        width=640, height=480, distortion_model="plumb_bob", d=[1.0, 2.0, 3.0, 4.0, 5.0]
    )
    ros.k = [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0]
    ros.r = [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0]
    ros.p = [1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0]
    gz = camera_info_to_gz(ros)
    assert list(gz.distortion.k) == [1.0, 2.0, 3.0, 4.0, 5.0]
    assert camera_info_to_ros(gz) == ros


def test_camera_info_drops_binning_and_maps_unknown_model_to_plumb_bob() -> None:
    ros = CameraInfo(distortion_model="fisheye", binning_x=2)
    gz = camera_info_to_gz(ros)
    for name in ("distortion", "intrinsics", "projection"):
        assert gz.HasField(name)
    back = camera_info_to_ros(gz)
    assert (back.distortion_model, back.binning_x) == ("plumb_bob", 0)


def test_camera_info_without_submessages_and_with_long_arrays() -> None:
    gz = GzCameraInfo()
    gz.rectification_matrix.extend([float(i) for i in range(12)])
    ros = camera_info_to_ros(gz)
    assert (ros.distortion_model, list(ros.d)) == ("", [])
    assert list(ros.k) == [0.0] * 9
    assert list(ros.r) == [float(i) for i in range(9)]
    gz.distortion.model = 2
    gz.intrinsics.k.extend([5.0, 6.0])
    ros = camera_info_to_ros(gz)
    assert ros.distortion_model == "equidistant"
    assert list(ros.k) == [5.0, 6.0] + [0.0] * 7

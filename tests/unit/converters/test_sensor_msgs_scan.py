"""sensor_msgs LaserScan, Range and PointCloud2 (docs/conversions-per-package.md §3.5)."""

from __future__ import annotations

import math
import struct

import pytest
from sensor_msgs.msg import LaserScan, PointCloud2, PointField, Range

from ros_gz_bridge_py.converters.sensor_msgs_scan import (
    laser_scan_to_gz,
    laser_scan_to_ros,
    point_cloud2_to_gz,
    point_cloud2_to_ros,
    range_to_gz,
    range_to_ros,
    scan_count,
)
from ros_gz_bridge_py.errors import ConversionError
from ros_gz_bridge_py.msgs import message_class

GzLaserScan = message_class("gz.msgs.LaserScan")
GzPointCloudPacked = message_class("gz.msgs.PointCloudPacked")


def test_upstream_fixture_count_is_100() -> None:
    ros = LaserScan(angle_min=-1.57, angle_max=1.57, angle_increment=3.14 / 100)
    ros.range_min, ros.range_max = 1.0, 2.0
    ros.ranges = [0.0] * 100
    ros.intensities = [1.0] * 100
    ros.header.frame_id = "lidar"
    gz = laser_scan_to_gz(ros)
    assert (gz.count, len(gz.ranges), len(gz.intensities), gz.frame) == (100, 100, 100, "lidar")
    assert gz.vertical_count == 0
    back = laser_scan_to_ros(gz)
    assert back.angle_increment == ros.angle_increment
    assert list(back.ranges) == list(ros.ranges)
    assert back.header.frame_id == "lidar"


def test_gazebo_style_scan_of_640_samples_converts_639() -> None:
    assert scan_count(-1.396263, 1.396263, 2 * 1.396263 / 639) == 639
    assert scan_count(0.0, 1.0, 0.25) == 4


def test_missing_intensities_are_zero_padded() -> None:
    ros = LaserScan(angle_min=0.0, angle_max=1.0, angle_increment=0.5, ranges=[1.0, 2.0, 3.0])
    gz = laser_scan_to_gz(ros)
    assert list(gz.ranges) == [1.0, 2.0]
    assert list(gz.intensities) == [0.0, 0.0]


def test_a_sample_count_the_message_does_not_carry_is_refused_past_the_bound() -> None:
    """A 5-byte Gazebo scan stating 10 million samples made an 80 MB ROS message (and a
    count of 2**32 - 1 would exhaust memory); a ROS scan whose angles state 100 million
    samples and carries none likewise. Padding within the bound stays (the test above)."""
    with pytest.raises(ConversionError, match=r"10000000 LaserScan samples from a message of 5 "):
        laser_scan_to_ros(GzLaserScan(count=10_000_000))
    ros = LaserScan(angle_min=0.0, angle_max=1.0, angle_increment=1e-8)
    with pytest.raises(ConversionError, match=r"LaserScan samples from a message of 0 bytes"):
        laser_scan_to_gz(ros)
    carried = GzLaserScan(count=100_000)
    carried.ranges.extend([1.5] * 100_000)  # no intensities: padded, within the bound
    assert list(laser_scan_to_ros(carried).intensities[-2:]) == [0.0, 0.0]


def test_bad_angles_are_rejected() -> None:
    with pytest.raises(ConversionError, match="angle_increment"):
        laser_scan_to_gz(LaserScan(angle_min=0.0, angle_max=1.0, angle_increment=0.0))
    with pytest.raises(ConversionError, match="angle_increment"):
        laser_scan_to_gz(LaserScan(angle_min=1.0, angle_max=0.0, angle_increment=0.5))


def test_multi_row_scan_takes_the_middle_row_and_frame() -> None:
    gz = GzLaserScan(count=3, vertical_count=4, frame="robot::lidar")
    gz.ranges.extend([float(i) for i in range(12)])
    gz.header.data.add(key="frame_id", value=["overwritten"])
    ros = laser_scan_to_ros(gz)
    assert list(ros.ranges) == [6.0, 7.0, 8.0]
    assert list(ros.intensities) == [0.0, 0.0, 0.0]
    assert ros.header.frame_id == "robot/lidar"


def test_range_round_trips_through_a_one_sample_scan() -> None:
    ros = Range(field_of_view=0.5, min_range=0.25, max_range=14.0, range=3.5)
    ros.header.frame_id = "sonar"
    gz = range_to_gz(ros)
    assert (gz.count, list(gz.ranges), gz.angle_min, gz.angle_max) == (1, [3.5], -0.25, 0.25)
    assert range_to_ros(gz) == ros


def test_range_from_a_narrow_lidar_takes_the_nearest_return() -> None:
    gz = GzLaserScan(angle_min=-0.02, angle_max=0.02, range_min=0.1, range_max=14.0, count=3)
    gz.ranges.extend([5.0, math.nan, 2.5, math.inf])
    ros = range_to_ros(gz)
    assert ros.range == 2.5
    assert ros.field_of_view == pytest.approx(0.04)
    with pytest.raises(ConversionError, match="no ranges"):
        range_to_ros(GzLaserScan())


def test_point_cloud_upstream_fixture_round_trips() -> None:
    ros = PointCloud2(height=4, width=2, point_step=4, row_step=8, is_dense=True)
    ros.fields = [PointField(name="x", offset=0, datatype=PointField.FLOAT32, count=1)]
    ros.data = struct.pack("<8f", *range(8))
    gz = point_cloud2_to_gz(ros)
    assert gz.field[0].datatype == 6  # gz FLOAT32
    assert gz.data == ros.data.tobytes()
    assert point_cloud2_to_ros(gz) == ros


def test_point_cloud_row_padding_and_empty_fields_are_consistent() -> None:
    ros = PointCloud2(height=2, width=2, point_step=6, row_step=13, is_dense=False)
    ros.fields = [
        PointField(name="x", offset=0, datatype=PointField.FLOAT32, count=1),
        PointField(name="i", offset=4, datatype=PointField.UINT16, count=1),
        PointField(name="pad", offset=6, datatype=PointField.FLOAT64, count=0),
    ]
    ros.data = bytes(range(26))
    gz = point_cloud2_to_gz(ros)
    assert (gz.row_step, gz.data) == (13, bytes(range(26)))
    assert point_cloud2_to_ros(gz) == ros


def test_point_cloud_sizes_that_do_not_describe_the_data_are_rejected() -> None:
    """The cloud of issue 14: a consumer that trusts width reads 64 GiB from 16 bytes."""
    ros = PointCloud2(height=1, width=4_294_967_295, point_step=16, row_step=16, data=bytes(16))
    ros.fields = [PointField(name="x", offset=0, datatype=PointField.FLOAT32, count=1)]
    with pytest.raises(ConversionError) as error:
        point_cloud2_to_gz(ros)
    assert str(error.value) == (
        "sensor_msgs/msg/PointCloud2 sizes do not match its data: row_step is 16, less than "
        "width*point_step = 4294967295*16 = 68719476720"
    )
    gz = GzPointCloudPacked(height=2, width=1, point_step=4, row_step=4, data=bytes(9))
    gz.field.add(name="x", offset=2, datatype=2, count=2)  # INT16 x 2 from byte 2: 6 > 4
    with pytest.raises(ConversionError) as error:
        point_cloud2_to_ros(gz)
    assert str(error.value) == (
        "gz.msgs.PointCloudPacked sizes do not match its data: field[0] 'x' (2 x INT16) ends "
        "at offset+count*size = 2+2*2 = 6, past point_step = 4; data has 9 bytes, not "
        "height*row_step = 2*4 = 8"
    )


def test_point_cloud_unknown_datatypes_fall_back_to_int8() -> None:
    ros = PointCloud2(fields=[PointField(name="bad", datatype=0), PointField(name="d", datatype=8)])
    gz = point_cloud2_to_gz(ros)
    assert [f.datatype for f in gz.field] == [0, 7]
    gz.field[1].datatype = 0
    back = point_cloud2_to_ros(gz)
    assert [f.datatype for f in back.fields] == [PointField.INT8, PointField.INT8]

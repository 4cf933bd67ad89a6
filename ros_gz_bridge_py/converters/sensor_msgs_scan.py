"""sensor_msgs LaserScan, Range and PointCloud2 converters (docs/conversions-per-package.md §3.5).

Paired in sensor_msgs.py. ``sensor_msgs/msg/Range`` <-> ``gz.msgs.LaserScan`` follows
ros_gz PR #736 in spirit (a narrow Gazebo lidar used as a range finder); its upstream source
was not available to check, so the mapping below is our own and may differ in details:
- G→R: header as for LaserScan (frame_id from gz ``frame``); ``field_of_view`` =
  angle_max - angle_min; ``min_range``/``max_range`` from range_min/range_max; ``range`` =
  the smallest of all gz ranges (the nearest return, NaN ignored); ``radiation_type`` and
  ``variance`` stay 0.
- R→G: a one-sample scan: angles ±field_of_view/2, ``angle_step`` = field_of_view,
  ``count`` = 1, ``ranges`` = [range], range_min/range_max from min_range/max_range.

Differences from ros_gz_bridge:
- LaserScan R→G pads ranges/intensities shorter than ``count`` with 0.0 (C++ over-reads;
  an empty intensities array is common).
- LaserScan R→G raises ConversionError when (angle_max - angle_min) / angle_increment is not
  a finite non-negative number (UB in C++).
- LaserScan G→R pads gz ranges/intensities shorter than the selected row with 0.0.
- LaserScan, both ways: a sample count whose ranges and intensities would be more than
  ``converters/_limits.py`` allows for the message's size (a 5-byte scan stating 10 million
  samples and carrying none) raises ConversionError (C++ pads G→R, over-reads R→G).
- Range G→R raises ConversionError for a scan with no ranges.
- PointCloud2, both ways, raises ConversionError when the sizes do not describe the data
  (see :func:`check_cloud_sizes`; C++ forwards the message, and a consumer that trusts the
  sizes reads out of bounds).
"""

from __future__ import annotations

import math
from array import array
from dataclasses import dataclass
from typing import Any

import numpy as np
from sensor_msgs.msg import LaserScan, PointCloud2, PointField, Range

from ros_gz_bridge_py.bulk.cdr import layout_until
from ros_gz_bridge_py.bulk.path import BulkPath
from ros_gz_bridge_py.converters._fields import Value, fields, same
from ros_gz_bridge_py.converters._limits import check_output
from ros_gz_bridge_py.converters.std_msgs import HEADER, gz_to_ros_frame
from ros_gz_bridge_py.errors import ConversionError, SizeMismatchError
from ros_gz_bridge_py.msgs import message_class

GzLaserScan = message_class("gz.msgs.LaserScan")
GzPointCloudPacked = message_class("gz.msgs.PointCloudPacked")

#: ROS PointField datatype -> gz PointCloudPacked.Field.DataType: INT8..FLOAT64 are 1..8 / 0..7.
_GZ_INT8 = 0
_ROS_INT8 = PointField.INT8
_DATATYPE_OFFSET = PointField.INT8 - _GZ_INT8
_ROS_DATATYPES = range(PointField.INT8, PointField.FLOAT64 + 1)
#: PointField datatypes in order (ROS 1..8, gz 0..7): (name, bytes per element).
_DATATYPES = (
    ("INT8", 1),
    ("UINT8", 1),
    ("INT16", 2),
    ("UINT16", 2),
    ("INT32", 4),
    ("UINT32", 4),
    ("FLOAT32", 4),
    ("FLOAT64", 8),
)


def scan_count(angle_min: float, angle_max: float, angle_increment: float) -> int:
    """``uint32((max - min) / inc)`` evaluated in float32 arithmetic, as the C++ does."""
    span = np.float32(np.float32(angle_max) - np.float32(angle_min))
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = float(span / np.float32(angle_increment))
    if not math.isfinite(ratio) or ratio < 0:
        msg = (
            f"sensor_msgs/msg/LaserScan angles give no sample count: (angle_max={angle_max} - "
            f"angle_min={angle_min}) / angle_increment={angle_increment} = {ratio}"
        )
        raise ConversionError(msg)
    return int(ratio)


#: The bytes one sample writes: a float32 range and a float32 intensity.
_SAMPLE_BYTES = 8


def _check_samples(count: int, received: int) -> None:
    check_output(count, _SAMPLE_BYTES, "LaserScan samples", received)


def _first(values: Any, count: int) -> Any:
    """The first ``count`` values, zero-padded when there are fewer."""
    head = values[:count]
    if len(head) < count:
        head = list(head) + [0.0] * (count - len(head))
    return head


#: Header; R→G the frame_id also goes to gz ``frame``, G→R it always comes from there.
_SCAN_HEADER = fields(
    ("header", HEADER), ("header.frame_id", "frame", Value(same, gz_to_ros_frame))
)
_LASER_SCAN = fields(
    _SCAN_HEADER,
    "angle_min",
    "angle_max",
    ("angle_increment", "angle_step"),
    "range_min",
    "range_max",
)


def laser_scan_to_gz(ros: Any) -> Any:
    count = scan_count(ros.angle_min, ros.angle_max, ros.angle_increment)
    _check_samples(count, 4 * (len(ros.ranges) + len(ros.intensities)) + len(ros.header.frame_id))
    gz = GzLaserScan()
    _LASER_SCAN.to_gz(ros, gz)
    gz.count = count
    gz.ranges.extend(_first(ros.ranges, count))
    gz.intensities.extend(_first(ros.intensities, count))
    return gz


def laser_scan_to_ros(gz: Any) -> Any:
    """Only the middle row of a multi-row scan reaches ROS: row ``vertical_count // 2``."""
    ros = LaserScan()
    _LASER_SCAN.to_ros(gz, ros)
    count = gz.count
    _check_samples(count, gz.ByteSize())
    start = (gz.vertical_count // 2) * count
    ros.ranges = array("f", _first(gz.ranges[start : start + count], count))
    ros.intensities = array("f", _first(gz.intensities[start : start + count], count))
    return ros


def range_to_gz(ros: Any) -> Any:
    gz = GzLaserScan()
    _SCAN_HEADER.to_gz(ros, gz)
    half = float(ros.field_of_view) / 2.0
    gz.angle_min = -half
    gz.angle_max = half
    gz.angle_step = ros.field_of_view
    gz.range_min = ros.min_range
    gz.range_max = ros.max_range
    gz.count = 1
    gz.ranges.append(ros.range)
    return gz


def range_to_ros(gz: Any) -> Any:
    if not gz.ranges:
        msg = "gz.msgs.LaserScan has no ranges: cannot make a sensor_msgs/msg/Range"
        raise ConversionError(msg)
    ros = Range()
    _SCAN_HEADER.to_ros(gz, ros)
    ros.field_of_view = gz.angle_max - gz.angle_min
    ros.min_range = gz.range_min
    ros.max_range = gz.range_max
    ros.range = float(np.nanmin(np.asarray(gz.ranges, dtype=np.float64)))
    return ros


@dataclass(frozen=True)
class CloudSizes:
    """The size fields of a point cloud, as the sender wrote them (same names on both sides)."""

    height: int
    width: int
    point_step: int
    row_step: int
    #: (name, offset, count, datatype) of each field, datatype in the sender's numbering.
    fields: list[tuple[str, int, int, int]]
    #: The sender's value for INT8 (ROS 1, gz 0).
    int8: int


def check_cloud_sizes(type_name: str, fields_name: str, sizes: CloudSizes, data_size: int) -> None:
    """Raise ConversionError unless the sizes describe ``data_size`` bytes of data exactly.

    What a consumer that trusts the sizes needs: every field (count elements of its datatype,
    an unknown datatype counting as the INT8 it becomes) inside ``point_step``; a row of
    ``width`` points inside ``row_step`` (longer is row padding); and exactly ``height`` rows
    of ``row_step`` bytes (PCL copies all of ``data`` into a width x height cloud). The
    products are Python ints, exact: 4294967295*16 is not wrapped as in uint32 arithmetic.
    The error names every size that is wrong, its value and what it should be.
    """
    height, width = sizes.height, sizes.width
    point_step, row_step = sizes.point_step, sizes.row_step
    problems = []
    for index, (name, offset, count, datatype) in enumerate(sizes.fields):
        number = datatype - sizes.int8
        if 0 <= number < len(_DATATYPES):
            kind, size = _DATATYPES[number]
        else:
            kind, size = f"datatype {datatype} taken as INT8", 1
        end = offset + count * size
        if end > point_step:
            problems.append(
                f"{fields_name}[{index}] {name!r} ({count} x {kind}) ends at "
                f"offset+count*size = {offset}+{count}*{size} = {end}, past point_step = "
                f"{point_step}"
            )
    if row_step < width * point_step:
        problems.append(
            f"row_step is {row_step}, less than width*point_step = {width}*{point_step} = "
            f"{width * point_step}"
        )
    if data_size != height * row_step:
        problems.append(
            f"data has {data_size} bytes, not height*row_step = {height}*{row_step} = "
            f"{height * row_step}"
        )
    if problems:
        msg = f"{type_name} sizes do not match its data: {'; '.join(problems)}"
        raise SizeMismatchError(msg)


def _checked_fields(
    type_name: str, fields_name: str, cloud: Any, int8: int, data_size: int
) -> list[tuple[str, int, int, int]]:
    """(name, offset, count, datatype) of each point field of ``cloud`` (in its field
    ``fields_name``), once :func:`check_cloud_sizes` has found that the sizes describe the data."""
    described = [(f.name, f.offset, f.count, f.datatype) for f in getattr(cloud, fields_name)]
    sizes = CloudSizes(cloud.height, cloud.width, cloud.point_step, cloud.row_step, described, int8)
    check_cloud_sizes(type_name, fields_name, sizes, data_size)
    return described


#: Every field of a point cloud but ``fields`` and ``data``; the names are the same both sides.
_CLOUD = fields(
    ("header", HEADER), "height", "width", "is_bigendian", "point_step", "row_step", "is_dense"
)


def point_cloud2_meta_to_gz(ros: Any, data_size: int) -> tuple[Any, int]:
    """Every field but ``data`` (all of which is taken). An unknown ROS datatype becomes gz
    INT8, silently, as in C++.

    Raises:
        ConversionError: the sizes do not describe the data (:func:`check_cloud_sizes`).
    """
    point_fields = _checked_fields(
        "sensor_msgs/msg/PointCloud2", "fields", ros, _ROS_INT8, data_size
    )
    gz = GzPointCloudPacked()
    _CLOUD.to_gz(ros, gz)
    for name, offset, count, datatype in point_fields:
        gz.field.add(
            name=name,
            offset=offset,
            count=count,
            datatype=datatype - _DATATYPE_OFFSET if datatype in _ROS_DATATYPES else _GZ_INT8,
        )
    return gz, data_size


def point_cloud2_to_gz(ros: Any) -> Any:
    data = ros.data
    gz, _ = point_cloud2_meta_to_gz(ros, len(data))
    gz.data = bytes(data)
    return gz


def point_cloud2_meta_to_ros(gz: Any, data_size: int) -> tuple[Any, int]:
    """Every field but ``data`` (all of which is taken). An unknown gz datatype becomes ROS
    INT8, silently, as in C++.

    Raises:
        ConversionError: the sizes do not describe the data (:func:`check_cloud_sizes`).
    """
    point_fields = _checked_fields("gz.msgs.PointCloudPacked", "field", gz, _GZ_INT8, data_size)
    ros = PointCloud2()
    _CLOUD.to_ros(gz, ros)
    ros.fields = [
        PointField(name=name, offset=offset, count=count, datatype=_ros_datatype(datatype))
        for name, offset, count, datatype in point_fields
    ]
    return ros, data_size


def _ros_datatype(gz_datatype: int) -> int:
    datatype = gz_datatype + _DATATYPE_OFFSET
    return datatype if datatype in _ROS_DATATYPES else int(_ROS_INT8)


def point_cloud2_to_ros(gz: Any) -> Any:
    data = gz.data
    ros, _ = point_cloud2_meta_to_ros(gz, len(data))
    ros.data = data
    return ros


#: PointCloud2 on the bulk path: gz ``data`` is field 8; in ROS only ``is_dense`` follows it.
POINT_CLOUD2_BULK = BulkPath(
    gz_field=8,
    ros_layout=layout_until(PointCloud2, "data"),
    gz_meta_to_ros=point_cloud2_meta_to_ros,
    ros_meta_to_gz=point_cloud2_meta_to_gz,
)

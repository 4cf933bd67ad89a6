"""The messages of the end-to-end tests and what the bridge must make of them.

Each :class:`GzSample` is a Gazebo message in protobuf text format, valid for both the
ign-msgs 8 definitions of our C++ peer and gz-msgs 10 (Harmonic), with the ROS message the
conversion rules (``docs/conversions.md``) say must come out of it. Each
:class:`RosSample` is a ROS message and the Gazebo message it must become. Every value the
conversion keeps is distinctive, and every number is exact in float32, so float32 and float64
fields compare with ``==``.
"""

from __future__ import annotations

import math
import struct
from dataclasses import dataclass, field
from typing import Any


def text_bytes(data: bytes) -> str:
    """``data`` as a protobuf text-format string literal (octal escapes)."""
    return '"' + "".join(f"\\{byte:03o}" for byte in data) + '"'


def gz_header(sec: int, nsec: int, *entries: tuple[str, str]) -> str:
    """A text-format gz ``header`` with the given ``data`` entries (key, single value)."""
    data = " ".join(f'data {{ key: "{key}" value: "{value}" }}' for key, value in entries)
    return f"header {{ stamp {{ sec: {sec} nsec: {nsec} }} {data} }}"


def ros_header(sec: int, nanosec: int, frame_id: str) -> dict[str, Any]:
    return {"stamp": {"sec": sec, "nanosec": nanosec}, "frame_id": frame_id}


@dataclass(frozen=True)
class HarmonicField:
    """A field of a Harmonic message that the Fortress definitions lack (or number differently).

    The C++ peer appends it to the serialized payload (``--field``); a Python publisher with
    the gz-msgs 10 definitions sets it by ``name``.
    """

    number: int
    name: str
    #: The submessage type without its package, e.g. ``Float_V``.
    type_name: str
    text: str


@dataclass(frozen=True)
class GzSample:
    """A Gazebo message to publish and the ROS message (field values) that must arrive."""

    #: The type without its package, e.g. ``Clock``.
    type_name: str
    text: str
    ros: dict[str, Any]
    harmonic_fields: tuple[HarmonicField, ...] = field(default=())

    @property
    def ign_type(self) -> str:
        return f"ignition.msgs.{self.type_name}"

    @property
    def gz_type(self) -> str:
        return f"gz.msgs.{self.type_name}"

    def peer_pub_args(self, topic: str, wire_type: str | None = None) -> list[str]:
        """Arguments of ``ign_peer pub`` publishing this sample at 5 Hz for at most 90 s."""
        args = ["pub", topic, self.ign_type, "5", "450", self.text, "--wait", "0", "--settle", "0"]
        if wire_type is not None:
            args += ["--wire-type", wire_type]
        for extra in self.harmonic_fields:
            args += ["--field", f"{extra.number} ignition.msgs.{extra.type_name} {extra.text}"]
        return args

    @property
    def harmonic_text(self) -> str:
        """The whole message in gz-msgs 10 text format."""
        extras = " ".join(f"{extra.name} {{ {extra.text} }}" for extra in self.harmonic_fields)
        return f"{self.text} {extras}".strip()


@dataclass(frozen=True)
class RosSample:
    """A ROS message (field values) to publish and the Gazebo message (text) it must become."""

    ros_type: str
    values: dict[str, Any]
    gz_type_name: str
    gz_text: str


def _pattern(size: int, seed: int) -> bytes:
    return bytes((index * 7 + index // 251 + seed) % 256 for index in range(size))


_ZEROS_36 = [0.0] * 36
_ZEROS_9 = [0.0] * 9

CLOCK = GzSample(
    "Clock",
    "system { sec: 7 nsec: 8 } real { sec: 9 nsec: 10 } sim { sec: 1234 nsec: 1500000123 }",
    # nsec >= 1e9 is carried into the seconds (docs/conversions-per-package.md §3.8).
    {"clock": {"sec": 1235, "nanosec": 500000123}},
)

JOINT_STATES = GzSample(
    "Model",
    gz_header(11, 22, ("frame_id", "waffle::base_link"))
    + ' name: "waffle"'
    + ' joint { name: "wheel_left_joint" axis1 { position: 1.5 velocity: -0.25 force: 3.75 } }'
    + ' joint { name: "wheel_right_joint" axis1 { position: -2.5 velocity: 0.125 force: -4.5 } }'
    + ' joint { name: "caster_joint" }',
    {
        "header": ros_header(11, 22, "waffle/base_link"),
        "name": ["wheel_left_joint", "wheel_right_joint", "caster_joint"],
        "position": [1.5, -2.5, 0.0],
        "velocity": [-0.25, 0.125, 0.0],
        "effort": [3.75, -4.5, 0.0],
    },
)

ODOMETRY = GzSample(
    "Odometry",
    gz_header(21, 42, ("frame_id", "odom"), ("child_frame_id", "waffle::base_footprint"))
    + " pose { position { x: 1.5 y: -2.25 z: 0.125 }"
    + " orientation { x: 0.5 y: -0.5 z: 0.25 w: 0.75 } }"
    + " twist { linear { x: 0.75 y: -0.125 z: 0.0625 } angular { x: -0.5 y: 0.375 z: 1.25 } }",
    {
        "header": ros_header(21, 42, "odom"),
        "child_frame_id": "waffle/base_footprint",
        "pose": {
            "pose": {
                "position": {"x": 1.5, "y": -2.25, "z": 0.125},
                "orientation": {"x": 0.5, "y": -0.5, "z": 0.25, "w": 0.75},
            },
            "covariance": _ZEROS_36,
        },
        "twist": {
            "twist": {
                "linear": {"x": 0.75, "y": -0.125, "z": 0.0625},
                "angular": {"x": -0.5, "y": 0.375, "z": 1.25},
            },
            "covariance": _ZEROS_36,
        },
    },
)

TF = GzSample(
    "Pose_V",
    # The Pose_V header and the pose names are ignored (docs/conversions-per-package.md §3.7).
    gz_header(1, 2, ("frame_id", "ignored_top_frame"))
    + " pose { "
    + gz_header(31, 62, ("frame_id", "odom"), ("child_frame_id", "waffle::base_footprint"))
    + ' name: "ignored_name" position { x: 1 y: 2 z: 3 } orientation { x: 0 y: 0 z: 0.5 w: 0.75 } }'
    + " pose { "
    + gz_header(32, 64, ("frame_id", "waffle::base_link"), ("child_frame_id", "waffle::imu"))
    + " position { x: -0.5 y: 0.25 z: 0.125 } orientation { x: 0.25 y: -0.25 z: 0 w: 1 } }",
    {
        "transforms": [
            {
                "header": ros_header(31, 62, "odom"),
                "child_frame_id": "waffle/base_footprint",
                "transform": {
                    "translation": {"x": 1.0, "y": 2.0, "z": 3.0},
                    "rotation": {"x": 0.0, "y": 0.0, "z": 0.5, "w": 0.75},
                },
            },
            {
                "header": ros_header(32, 64, "waffle/base_link"),
                "child_frame_id": "waffle/imu",
                "transform": {
                    "translation": {"x": -0.5, "y": 0.25, "z": 0.125},
                    "rotation": {"x": 0.25, "y": -0.25, "z": 0.0, "w": 1.0},
                },
            },
        ]
    },
)


def _float_v(values: list[float]) -> str:
    return "data: [" + ", ".join(str(value) for value in values) + "]"


IMU_HARMONIC = GzSample(
    "IMU",
    gz_header(41, 82, ("frame_id", "waffle::imu_link"))
    + ' entity_name: "imu_sensor" orientation { x: 0.125 y: 0.25 z: -0.5 w: 0.75 }',
    {
        "header": ros_header(41, 82, "waffle/imu_link"),
        "orientation": {"x": 0.125, "y": 0.25, "z": -0.5, "w": 0.75},
        "orientation_covariance": [float(value) for value in range(1, 10)],
        "angular_velocity": {"x": 0.5, "y": -1.5, "z": 2.5},
        "angular_velocity_covariance": [float(value) for value in range(11, 20)],
        "linear_acceleration": {"x": -9.75, "y": 0.25, "z": 9.8125},
        "linear_acceleration_covariance": [float(value) for value in range(21, 30)],
    },
    harmonic_fields=(
        # Harmonic numbering (docs/protocol-lines.md §9.4): 4, 6, 8 are covariances, 5 and 7
        # vectors.
        HarmonicField(4, "orientation_covariance", "Float_V", _float_v(list(range(1, 10)))),
        HarmonicField(5, "angular_velocity", "Vector3d", "x: 0.5 y: -1.5 z: 2.5"),
        HarmonicField(6, "angular_velocity_covariance", "Float_V", _float_v(list(range(11, 20)))),
        HarmonicField(7, "linear_acceleration", "Vector3d", "x: -9.75 y: 0.25 z: 9.8125"),
        HarmonicField(
            8, "linear_acceleration_covariance", "Float_V", _float_v(list(range(21, 30)))
        ),
    ),
)

IMU_FORTRESS = GzSample(
    "IMU",
    gz_header(42, 84, ("frame_id", "fortress::imu"))
    + ' entity_name: "imu" orientation { x: -0.25 y: 0.5 z: 0.125 w: 0.8125 }'
    + " angular_velocity { x: 0.75 y: -0.5 z: 1.5 }"
    + " linear_acceleration { x: 0.25 y: -0.125 z: 9.75 }",
    {
        "header": ros_header(42, 84, "fortress/imu"),
        "orientation": {"x": -0.25, "y": 0.5, "z": 0.125, "w": 0.8125},
        "orientation_covariance": _ZEROS_9,
        "angular_velocity": {"x": 0.75, "y": -0.5, "z": 1.5},
        "angular_velocity_covariance": _ZEROS_9,
        "linear_acceleration": {"x": 0.25, "y": -0.125, "z": 9.75},
        "linear_acceleration_covariance": _ZEROS_9,
    },
)

_SCAN_RANGES = [0.25 * index for index in range(1, 16)]
SCAN = GzSample(
    "LaserScan",
    # Three rows of five samples: the bridge takes the middle row (docs/conversions-per-package.md
    # §3.5), and the header frame is overwritten with `frame`.
    gz_header(51, 102, ("frame_id", "header_frame"))
    + ' frame: "waffle::base_scan" angle_min: -1.5 angle_max: 1.5 angle_step: 0.75'
    + " range_min: 0.125 range_max: 3.5 count: 5 vertical_count: 3"
    + " vertical_angle_min: -0.5 vertical_angle_max: 0.5 vertical_angle_step: 0.5"
    + " ranges: ["
    + ", ".join(str(value) for value in _SCAN_RANGES)
    + "] intensities: ["
    + ", ".join(str(value) for value in range(1, 16))
    + "]",
    {
        "header": ros_header(51, 102, "waffle/base_scan"),
        "angle_min": -1.5,
        "angle_max": 1.5,
        "angle_increment": 0.75,
        "time_increment": 0.0,
        "scan_time": 0.0,
        "range_min": 0.125,
        "range_max": 3.5,
        "ranges": _SCAN_RANGES[5:10],
        "intensities": [float(value) for value in range(6, 11)],
    },
)

_K = [400.5, 0.0, 16.5, 0.0, 401.25, 12.5, 0.0, 0.0, 1.0]
_P = [400.5, 0.0, 16.5, -2.5, 0.0, 401.25, 12.5, 0.0, 0.0, 0.0, 1.0, 0.0]
_R = [1.0, 0.0, 0.0, 0.0, 0.5, -0.5, 0.0, 0.5, 0.5]
_D = [0.125, -0.25, 0.0625, 0.5, -0.75, 1.0, 2.0, 3.0]


def _doubles(values: list[float]) -> str:
    return "[" + ", ".join(str(value) for value in values) + "]"


CAMERA_INFO = GzSample(
    "CameraInfo",
    gz_header(61, 122, ("frame_id", "waffle::camera_rgb_optical_frame"))
    + " width: 32 height: 24"
    + f" distortion {{ model: RATIONAL_POLYNOMIAL k: {_doubles(_D)} }}"
    + f" intrinsics {{ k: {_doubles(_K)} }}"
    + f" projection {{ p: {_doubles(_P)} }}"
    + f" rectification_matrix: {_doubles(_R)}",
    {
        "header": ros_header(61, 122, "waffle/camera_rgb_optical_frame"),
        "height": 24,
        "width": 32,
        "distortion_model": "rational_polynomial",
        "d": _D,
        "k": _K,
        "r": _R,
        "p": _P,
        "binning_x": 0,
        "binning_y": 0,
    },
)

_RGB = _pattern(32 * 24 * 3, seed=3)
IMAGE = GzSample(
    "Image",
    gz_header(71, 142, ("frame_id", "camera::rgb"))
    + f" width: 32 height: 24 step: 96 pixel_format_type: RGB_INT8 data: {text_bytes(_RGB)}",
    {
        "header": ros_header(71, 142, "camera/rgb"),
        "height": 24,
        "width": 32,
        "encoding": "rgb8",
        "is_bigendian": 0,
        "step": 96,
        "data": list(_RGB),
    },
)

_DEPTH = struct.pack("<48f", *(0.5 * index for index in range(48)))
DEPTH_IMAGE = GzSample(
    "Image",
    gz_header(72, 144, ("frame_id", "camera::depth"))
    + f" width: 8 height: 6 step: 32 pixel_format_type: R_FLOAT32 data: {text_bytes(_DEPTH)}",
    {
        "header": ros_header(72, 144, "camera/depth"),
        "height": 6,
        "width": 8,
        "encoding": "32FC1",
        "is_bigendian": 0,
        "step": 32,
        "data": list(_DEPTH),
    },
)

_CLOUD = _pattern(2 * 3 * 12, seed=11)
POINTS = GzSample(
    "PointCloudPacked",
    gz_header(81, 162, ("frame_id", "camera::depth_frame"))
    + ' field { name: "x" offset: 0 datatype: FLOAT32 count: 1 }'
    + ' field { name: "rgb" offset: 4 datatype: UINT32 count: 1 }'
    + ' field { name: "ring" offset: 8 datatype: UINT16 count: 2 }'
    + " height: 2 width: 3 is_bigendian: true point_step: 12 row_step: 36"
    + f" data: {text_bytes(_CLOUD)} is_dense: true",
    {
        "header": ros_header(81, 162, "camera/depth_frame"),
        "height": 2,
        "width": 3,
        "fields": [
            {"name": "x", "offset": 0, "datatype": 7, "count": 1},
            {"name": "rgb", "offset": 4, "datatype": 6, "count": 1},
            {"name": "ring", "offset": 8, "datatype": 4, "count": 2},
        ],
        "is_bigendian": True,
        "point_step": 12,
        "row_step": 36,
        "data": list(_CLOUD),
        "is_dense": True,
    },
)

TWIST_FROM_GZ = GzSample(
    "Twist",
    "linear { x: 1.25 y: -0.75 z: 0.5 } angular { x: 0.25 y: -1.5 z: 3.5 }",
    {
        "linear": {"x": 1.25, "y": -0.75, "z": 0.5},
        "angular": {"x": 0.25, "y": -1.5, "z": 3.5},
    },
)

TWIST_TO_GZ = RosSample(
    "geometry_msgs/msg/Twist",
    {"linear": {"x": 0.25, "y": -0.5, "z": 0.125}, "angular": {"x": -0.75, "y": 1.5, "z": -2.25}},
    "Twist",
    "linear { x: 0.25 y: -0.5 z: 0.125 } angular { x: -0.75 y: 1.5 z: -2.25 }",
)

SCAN_TO_GZ = RosSample(
    "sensor_msgs/msg/LaserScan",
    {
        "header": ros_header(91, 182, "lidar::frame"),
        "angle_min": -1.5,
        "angle_max": 1.5,
        "angle_increment": 0.75,
        "time_increment": 0.5,
        "scan_time": 0.25,
        "range_min": 0.125,
        "range_max": 8.0,
        "ranges": [1.0, 2.0, 3.0, 4.0, 5.0],
        "intensities": [5.0, 4.0, 3.0, 2.0, 1.0],
    },
    "LaserScan",
    # count = trunc((max - min) / increment) = 4: the fifth sample is dropped
    # (docs/conversions-per-package.md §3.5).
    gz_header(91, 182, ("frame_id", "lidar::frame"))
    + ' frame: "lidar::frame" angle_min: -1.5 angle_max: 1.5 angle_step: 0.75'
    + " range_min: 0.125 range_max: 8 count: 4"
    + " ranges: [1, 2, 3, 4] intensities: [5, 4, 3, 2]",
)

#: A Clock a ROS node publishes where the bridge must not carry it to Gazebo.
CLOCK_FROM_ROS = {"clock": {"sec": 777, "nanosec": 555}}
#: A Twist a Gazebo node publishes where the bridge must not carry it to ROS.
TWIST_FROM_GZ_NOT_BRIDGED = GzSample(
    "Twist",
    "linear { x: -9.5 } angular { z: -8.5 }",
    {"linear": {"x": -9.5, "y": 0.0, "z": 0.0}, "angular": {"x": 0.0, "y": 0.0, "z": -8.5}},
)

#: What the Gazebo side publishes for each Gazebo->ROS entry of the real configurations.
SAMPLES_BY_GZ_TYPE = {
    "gz.msgs.Clock": CLOCK,
    "gz.msgs.Model": JOINT_STATES,
    "gz.msgs.Odometry": ODOMETRY,
    "gz.msgs.Pose_V": TF,
    "gz.msgs.IMU": IMU_HARMONIC,
    "gz.msgs.LaserScan": SCAN,
    "gz.msgs.CameraInfo": CAMERA_INFO,
    "gz.msgs.Image": IMAGE,
    "gz.msgs.PointCloudPacked": POINTS,
}


def sample_for(gz_type: str, topic: str) -> GzSample:
    """The sample for a configuration entry (a depth image for a topic named so)."""
    if gz_type == "gz.msgs.Image" and "depth" in topic:
        return DEPTH_IMAGE
    return SAMPLES_BY_GZ_TYPE[gz_type]


def mismatches(expected: Any, actual: Any, path: str = "msg") -> list[str]:
    """Where ``actual`` differs from ``expected`` (keys missing from ``expected`` are free)."""
    if isinstance(expected, dict):
        if not isinstance(actual, dict):
            return [f"{path}: expected a message, got {actual!r}"]
        found: list[str] = []
        for key, value in expected.items():
            if key not in actual:
                found.append(f"{path}.{key}: missing")
            else:
                found += mismatches(value, actual[key], f"{path}.{key}")
        return found
    if isinstance(expected, list):
        if not isinstance(actual, list) or len(actual) != len(expected):
            return [f"{path}: expected {expected!r}, got {actual!r}"]
        return [
            problem
            for index, (want, got) in enumerate(zip(expected, actual, strict=True))
            for problem in mismatches(want, got, f"{path}[{index}]")
        ]
    if isinstance(expected, float) and isinstance(actual, float) and math.isnan(expected):
        return [] if math.isnan(actual) else [f"{path}: expected nan, got {actual!r}"]
    return [] if expected == actual else [f"{path}: expected {expected!r}, got {actual!r}"]

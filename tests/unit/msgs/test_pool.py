"""The gz.msgs loader: fresh descriptor set, every bridged type present, golden wire bytes."""

from __future__ import annotations

import os
import shutil
import struct
import subprocess
import sys
from pathlib import Path

import pytest

from ros_gz_bridge_py.errors import UnsupportedTypeError
from ros_gz_bridge_py.msgs import GENERIC_TYPE, known_types, message_class, regen

# The gz types of the bridged pairs (docs/conversions.md §2) and of the ControlWorld
# service (docs/conversions-per-package.md §3.14), plus the types transport and services build on.
BRIDGED_TYPES = (
    "Actuators",
    "Altimeter",
    "AnnotatedAxisAligned2DBox",
    "AnnotatedAxisAligned2DBox_V",
    "AnnotatedOriented3DBox",
    "AnnotatedOriented3DBox_V",
    "Any",
    "BatteryState",
    "Boolean",
    "CameraInfo",
    "Clock",
    "Color",
    "Contact",
    "Contacts",
    "Dataframe",
    "Double",
    "Empty",
    "Entity",
    "EntityWrench",
    "Float",
    "Float_V",
    "FluidPressure",
    "GUICamera",
    "Header",
    "IMU",
    "Image",
    "Int32",
    "JointTrajectory",
    "JointWrench",
    "Joy",
    "LaserScan",
    "Light",
    "Magnetometer",
    "MaterialColor",
    "Model",
    "NavSat",
    "Odometry",
    "OdometryWithCovariance",
    "Param",
    "Param_V",
    "PointCloudPacked",
    "Pose",
    "PoseWithCovariance",
    "Pose_V",
    "Quaternion",
    "SensorNoise",
    "StringMsg",
    "StringMsg_V",
    "Time",
    "TrackVisual",
    "Twist",
    "TwistWithCovariance",
    "UInt32",
    "Vector3d",
    "VideoRecord",
    "WorldControl",
    "WorldReset",
    "Discovery",
    "Bytes",
    "EntityFactory",
    "WorldStatistics",
    "Joint",
    "Axis",
    # Added for issue 16: pairs of later ros_gz releases, and Jetty's NavSatWithCovariance.
    "AirSpeed",
    "DVLVelocityTracking",
    "LogicalCameraImage",
    "LogPlaybackStatistics",
    "NavSatWithCovariance",
)

# Whole UDP datagrams sent by ign-transport 11.0.0 (frames 1, 3, 5 and 6 of a capture,
# docs/protocol-zmq-discovery.md §2.3.2): uint16 little-endian body length, then the Discovery body.
PROCESS_UUID = "8fac3557-a1af-460e-92b0-1c45be37ee4e"
PUBLISHER_UUID = "ce706bf2-4115-4b4c-9992-067a4b7ce765"
HEARTBEAT = bytes.fromhex(
    "2a00100a1a2438666163333535372d613161662d343630652d393262302d3163343562653337656534652004"
)
SUBSCRIBE = bytes.fromhex(
    "3a00100a1a2438666163333535372d613161662d343630652d393262302d316334356265333765653465"
    "2002320e0a0c402f766d3a726f6f74402f78"
)
ADVERTISE = bytes.fromhex(
    "ce00100a1a2463653730366266322d343131352d346234632d393939322d3036376134623763653736352001"
    "3aa1010a0c402f766d3a726f6f74402f7812157463703a2f2f3132372e302e302e313a33373534311a246365"
    "3730366266322d343131352d346234632d393939322d303637613462376365373635222430646335653333"
    "642d666131332d343737372d386163612d6261336634623964653966642802322c0a06756e757365641217"
    "69676e6974696f6e2e6d7367732e537472696e674d736720ffffffffffffffffff01"
)
NEW_CONNECTION = bytes.fromhex(
    "ec00100a1a2438666163333535372d613161662d343630652d393262302d3163343562653337656534652006"
    "3abf010a0c402f766d3a726f6f74402f7812157463703a2f2f3132372e302e302e313a33373534311a243866"
    "6163333535372d613161662d343630652d393262302d316334356265333765653465222438356461346261"
    "352d363134652d343934632d613962662d3265363663376334663937352802324a0a246365373036626632"
    "2d343131352d346234632d393939322d303637613462376365373635121769676e6974696f6e2e6d736773"
    "2e537472696e674d736720ffffffffffffffffff01"
)
UINT64_MAX = 2**64 - 1
REPO_ROOT = Path(__file__).resolve().parents[3]


def _body(datagram: bytes) -> bytes:
    (length,) = struct.unpack_from("<H", datagram)
    assert length + 2 == len(datagram)
    return datagram[2:]


def test_committed_descriptor_set_is_fresh() -> None:
    if shutil.which("protoc") is None and not os.environ.get("PROTOC"):
        if os.environ.get("CI"):
            pytest.fail("protoc is missing in CI: install protobuf-compiler")
        pytest.skip("protoc not installed")
    assert regen.main(["--check"]) == 0


@pytest.mark.parametrize("name", BRIDGED_TYPES)
def test_every_bridged_type_has_a_class(name: str) -> None:
    cls = message_class(f"gz.msgs.{name}")
    assert cls.DESCRIPTOR.full_name == f"gz.msgs.{name}"
    assert f"gz.msgs.{name}" in known_types()


def test_known_types_are_sorted_top_level_names() -> None:
    names = known_types()
    assert names == sorted(names)
    assert "ignition.msgs.IMU" in names
    assert "gz.msgs.Header.Map" not in names
    assert all(n.startswith(("gz.msgs.", "ignition.msgs.")) for n in names)


def test_ignition_names_alias_gz_names_except_the_fortress_imu() -> None:
    assert message_class("ignition.msgs.StringMsg") is message_class("gz.msgs.StringMsg")
    fortress_imu = message_class("ignition.msgs.IMU")
    assert fortress_imu is not message_class("gz.msgs.IMU")
    assert fortress_imu.DESCRIPTOR.full_name == "ignition.msgs.IMU"


@pytest.mark.parametrize(
    "name", ["gz.msgs.NoSuchThing", "ignition.msgs.NoSuchThing", "std_msgs/msg/String", "", "IMU"]
)
def test_unknown_type_raises_unsupported_type_error(name: str) -> None:
    with pytest.raises(UnsupportedTypeError, match="known_types"):
        message_class(name)


def test_generic_type_is_not_a_message_class() -> None:
    with pytest.raises(UnsupportedTypeError):
        message_class(GENERIC_TYPE)


def test_imu_layouts_differ_as_the_versions_spec_says() -> None:
    harmonic = message_class("gz.msgs.IMU").DESCRIPTOR.fields_by_name
    fortress = message_class("ignition.msgs.IMU").DESCRIPTOR.fields_by_name
    assert {n: f.number for n, f in fortress.items()} == {
        "header": 1,
        "entity_name": 2,
        "orientation": 3,
        "angular_velocity": 4,
        "linear_acceleration": 5,
    }
    assert {n: f.number for n, f in harmonic.items()} == {
        "header": 1,
        "entity_name": 2,
        "orientation": 3,
        "orientation_covariance": 4,
        "angular_velocity": 5,
        "angular_velocity_covariance": 6,
        "linear_acceleration": 7,
        "linear_acceleration_covariance": 8,
    }
    assert fortress["header"].message_type.full_name == "gz.msgs.Header"


def test_fortress_imu_round_trips_its_own_layout() -> None:
    imu = message_class("ignition.msgs.IMU")(entity_name="imu_link")
    imu.angular_velocity.z = 0.5
    imu.linear_acceleration.z = 9.81
    wire = imu.SerializeToString()
    # field 4 (angular_velocity) then field 5 (linear_acceleration), both length-delimited
    assert b"\x22\x09\x21" in wire
    assert b"\x2a\x09\x21" in wire
    back = message_class("ignition.msgs.IMU").FromString(wire)
    assert (back.angular_velocity.z, back.linear_acceleration.z) == (0.5, 9.81)


@pytest.mark.parametrize("datagram", [HEARTBEAT, SUBSCRIBE, ADVERTISE, NEW_CONNECTION])
def test_observed_discovery_datagrams_reencode_byte_identically(datagram: bytes) -> None:
    body = _body(datagram)
    discovery = message_class("gz.msgs.Discovery").FromString(body)
    assert discovery.version == 10
    assert discovery.SerializeToString() == body


def test_heartbeat_fields() -> None:
    cls = message_class("gz.msgs.Discovery")
    heartbeat = cls.FromString(_body(HEARTBEAT))
    assert heartbeat.type == cls.HEARTBEAT
    assert heartbeat.process_uuid == PROCESS_UUID
    assert heartbeat.WhichOneof("disc_contents") is None


def test_subscribe_fields() -> None:
    cls = message_class("gz.msgs.Discovery")
    subscribe = cls.FromString(_body(SUBSCRIBE))
    assert subscribe.type == cls.SUBSCRIBE
    assert subscribe.WhichOneof("disc_contents") == "sub"
    assert subscribe.sub.topic == "@/vm:root@/x"


def test_advertise_built_from_values_matches_the_observed_bytes() -> None:
    cls = message_class("gz.msgs.Discovery")
    advertise = cls(version=10, process_uuid=PUBLISHER_UUID, type=cls.ADVERTISE)
    pub = advertise.pub
    pub.topic = "@/vm:root@/x"
    pub.address = "tcp://127.0.0.1:37541"
    pub.process_uuid = PUBLISHER_UUID
    pub.node_uuid = "0dc5e33d-fa13-4777-8aca-ba3f4b9de9fd"
    pub.scope = pub.ALL
    pub.msg_pub.ctrl = "unused"
    pub.msg_pub.msg_type = "ignition.msgs.StringMsg"
    pub.msg_pub.msgs_per_sec = UINT64_MAX
    body = advertise.SerializeToString()
    assert struct.pack("<H", len(body)) + body == ADVERTISE


def test_new_connection_carries_the_publisher_uuid_in_ctrl() -> None:
    cls = message_class("gz.msgs.Discovery")
    connection = cls.FromString(_body(NEW_CONNECTION))
    assert connection.type == cls.NEW_CONNECTION
    assert connection.pub.process_uuid == PROCESS_UUID
    assert connection.pub.WhichOneof("pub_type") == "msg_pub"
    assert connection.pub.msg_pub.ctrl == PUBLISHER_UUID
    assert connection.pub.msg_pub.throttled is False


def test_harmonic_discovery_types_exist() -> None:
    cls = message_class("gz.msgs.Discovery")
    assert (cls.SUBSCRIBERS_REQ, cls.SUBSCRIBERS_REP) == (8, 9)


def test_any_serializes_a_false_oneof_member() -> None:
    cls = message_class("gz.msgs.Any")
    value = cls(type=cls.BOOLEAN, bool_value=False)
    assert value.SerializeToString() == bytes.fromhex("10043000")


def test_reduced_model_skips_fields_it_does_not_declare() -> None:
    # Model field 7 (link, a submessage) is not declared by our reduced schema.
    wire = bytes.fromhex("1203626f74") + bytes.fromhex("3a0412026c31") + bytes.fromhex("4001")
    model = message_class("gz.msgs.Model").FromString(wire)
    assert (model.name, model.deleted) == ("bot", True)


def test_concurrent_first_lookups_share_one_class() -> None:
    # In a fresh interpreter, so the first load really is concurrent (and this process's
    # classes stay the ones other tests hold).
    script = (
        "from concurrent.futures import ThreadPoolExecutor\n"
        "from ros_gz_bridge_py.msgs import message_class\n"
        "with ThreadPoolExecutor(max_workers=8) as pool:\n"
        "    print(len(set(pool.map(message_class, ['gz.msgs.Clock'] * 32))))\n"
    )
    result = subprocess.run(
        [sys.executable, "-c", script], cwd=REPO_ROOT, capture_output=True, text=True, check=True
    )
    assert result.stdout.strip() == "1"

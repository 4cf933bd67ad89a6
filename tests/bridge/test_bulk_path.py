"""Images and point clouds both ways, and Twist ROS->Gazebo, on every publishing path.

The bridge runs three ways: the default bulk path (serialized messages, the DDS write through
rcl with the GIL released) with ROS->Gazebo messages read by ``ros_cdr``, the bulk path
publishing through rclpy's own serialized publish (``ROS_GZ_BRIDGE_SERIALIZED_PUBLISH=rclpy``),
and the object path with rclpy's message objects everywhere (``ROS_GZ_BRIDGE_BULK_PATH=off``,
``ROS_GZ_BRIDGE_LIGHT_READ=off``). ROS->Gazebo messages land in the real C++ ign-transport
echo, which parses them with the Debian gz-msgs; Gazebo->ROS messages come from the real C++
peer and our node, and land in rclpy. Every field is checked on arrival.
"""

from __future__ import annotations

import contextlib
import os
from collections.abc import Iterator
from dataclasses import dataclass
from typing import Any

import pytest
from geometry_msgs.msg import Twist
from sensor_msgs.msg import Image, PointCloud2, PointField

from ros_gz_bridge_py.app.settings import BULK_PATH_ENV as BULK_ENV
from ros_gz_bridge_py.app.settings import DDS_EVENT_BATCH_ENV
from ros_gz_bridge_py.bulk.path import gz_to_ros_cdr
from ros_gz_bridge_py.converters.registry import default_registry
from ros_gz_bridge_py.core.options import BULK_THREAD_NICE
from ros_gz_bridge_py.errors import ConversionError
from ros_gz_bridge_py.msgs import message_class
from ros_gz_bridge_py.transport import GzNode
from ros_gz_bridge_py.transport.zmq.bulk_context import THREAD_NAME_PREFIX
from testing.behaviour_harness import (
    WAIT,
    RosSide,
    bridge_command,
    gz_node,
    publish_until,
    ros_side,
    started,
)
from testing.e2e_harness import parse_gz
from testing.gzpeer import (
    PeerProcess,
    require_peer,
    start_peer,
    start_process,
    unique_name,
    wait_for_line,
    wait_until,
)
from tests.bridge.image_frames import pattern_bytes, rgb_frame, rgb_text_proto

__all__ = ["gz_node", "ros_side", "started"]

pytestmark = [pytest.mark.ros, pytest.mark.peer]

GZ_IMAGE = "gz.msgs.Image"
IMAGE = default_registry().get("sensor_msgs/msg/Image", GZ_IMAGE)
GZ_CLOUD = "gz.msgs.PointCloudPacked"
WIDTH, HEIGHT = 6, 4
VARIANTS = {
    "bulk": {},
    "bulk-rclpy-publish": {"ROS_GZ_BRIDGE_SERIALIZED_PUBLISH": "rclpy"},
    "object": {
        "ROS_GZ_BRIDGE_BULK_PATH": "off",
        "ROS_GZ_BRIDGE_LIGHT_READ": "off",
        DDS_EVENT_BATCH_ENV: "off",
    },
}


@dataclass(frozen=True)
class Topics:
    image_to_gz: str
    cloud_to_gz: str
    image_to_ros: str
    cloud_to_ros: str
    twist_to_gz: str


@dataclass
class RunningBridge:
    process: PeerProcess
    topics: Topics
    variant: str


@pytest.fixture(scope="module", params=list(VARIANTS))
def bridge(request: pytest.FixtureRequest) -> Iterator[RunningBridge]:
    require_peer()
    topics = Topics(
        unique_name("bulk_img_r2g"),
        unique_name("bulk_pc_r2g"),
        unique_name("bulk_img_g2r"),
        unique_name("bulk_pc_g2r"),
        unique_name("bulk_twist_r2g"),
    )
    command = bridge_command(
        f"{topics.image_to_gz}@sensor_msgs/msg/Image]{GZ_IMAGE}",
        f"{topics.cloud_to_gz}@sensor_msgs/msg/PointCloud2]{GZ_CLOUD}",
        f"{topics.image_to_ros}@sensor_msgs/msg/Image[{GZ_IMAGE}",
        f"{topics.cloud_to_ros}@sensor_msgs/msg/PointCloud2[{GZ_CLOUD}",
        f"{topics.twist_to_gz}@geometry_msgs/msg/Twist]gz.msgs.Twist",
    )
    process = start_process(command, {**os.environ, **VARIANTS[request.param]})
    try:
        for _ in range(5):
            wait_for_line(process, r"\]: Creating ", timeout=30)
        yield RunningBridge(process, topics, request.param)
    finally:
        process.stop()


def ros_image(index: int) -> Image:
    """A 6x4 bgr8 image whose every field differs from its neighbours and from 0."""
    msg = Image()
    msg.header.stamp.sec = 1_700_000_000 + index
    msg.header.stamp.nanosec = 123_456_789
    msg.header.frame_id = "camera/optical"
    msg.height, msg.width = HEIGHT, WIDTH
    msg.encoding = "bgr8"
    msg.step = WIDTH * 3 + 2  # row padding: gz recomputes the step and takes height*step bytes
    msg.data = bytes((7 * i + index) % 256 for i in range(HEIGHT * msg.step))
    return msg


def ros_twist(index: int) -> Twist:
    msg = Twist()
    msg.linear.x, msg.linear.y, msg.linear.z = 1.5 + index, -2.25, 3.125
    msg.angular.x, msg.angular.y, msg.angular.z = -4.5, 5.75, -6.875
    return msg


def ros_cloud(index: int) -> PointCloud2:
    msg = PointCloud2()
    msg.header.stamp.sec = 42 + index
    msg.header.stamp.nanosec = 987
    msg.header.frame_id = "lidar"
    msg.height, msg.width = 1, 5
    msg.fields = [
        PointField(name="x", offset=0, datatype=PointField.FLOAT32, count=1),
        PointField(name="ring", offset=4, datatype=PointField.UINT16, count=1),
    ]
    msg.is_bigendian = False
    msg.point_step, msg.row_step = 6, 30
    msg.data = bytes((11 * i + 3 + index) % 256 for i in range(30))
    msg.is_dense = True
    return msg


def _echo(topic: str, type_name: str, count: int = 1) -> PeerProcess:
    echo = start_peer("echo", topic, f"ignition.msgs.{type_name}", "30", "--count", str(count),
                      "--wire-type", f"gz.msgs.{type_name}")  # fmt: skip
    wait_for_line(echo, "READY", timeout=WAIT)
    return echo


def _messages(echo: PeerProcess, type_name: str) -> list[Any]:
    lines = [x for x in echo.output().splitlines() if x.startswith("MSG ")]
    return [parse_gz(type_name, line.split(" ", 2)[2]) for line in lines]


def _first_message(echo: PeerProcess, type_name: str) -> Any:
    return _messages(echo, type_name)[0]


@pytest.mark.parametrize(
    ("kind", "make", "ros_type", "gz_type", "type_name"),
    [
        ("image", ros_image, "sensor_msgs/msg/Image", GZ_IMAGE, "Image"),
        ("cloud", ros_cloud, "sensor_msgs/msg/PointCloud2", GZ_CLOUD, "PointCloudPacked"),
        ("twist", ros_twist, "geometry_msgs/msg/Twist", "gz.msgs.Twist", "Twist"),
    ],
)
def test_ros_to_gazebo(  # noqa: PLR0917 - one parametrized case per message kind
    bridge: RunningBridge,
    ros_side: RosSide,
    started: list[PeerProcess],
    kind: str,
    make: object,
    ros_type: str,
    gz_type: str,
    type_name: str,
) -> None:
    topic = {
        "image": bridge.topics.image_to_gz,
        "cloud": bridge.topics.cloud_to_gz,
        "twist": bridge.topics.twist_to_gz,
    }[kind]
    echo = _echo(topic, type_name)
    started.append(echo)
    assert callable(make)
    first = make(0)
    publisher = ros_side.run(lambda: ros_side.node.create_publisher(type(first), topic, 10))
    sent: list[object] = []

    def publish(index: int) -> None:
        sent.append(make(index))
        ros_side.run(lambda: publisher.publish(sent[-1]))

    publish_until(publish, lambda: "MSG " in echo.output(), f"the echo receives {kind}")
    got = _first_message(echo, type_name)
    pair = default_registry().get(ros_type, gz_type)
    assert got in [pair.to_gz(msg) for msg in sent]
    if kind == "image":
        assert got.pixel_format_type == 8  # BGR_INT8
        assert got.step == WIDTH * 3
        assert len(got.data) == HEIGHT * WIDTH * 3
        # The two bytes of row padding of each ROS row are left out, row by row.
        step, row = WIDTH * 3 + 2, WIDTH * 3
        sent_data = [bytes(getattr(msg, "data", b"")) for msg in sent]
        assert got.data in [
            b"".join(data[r * step : r * step + row] for r in range(HEIGHT)) for data in sent_data
        ]
    elif kind == "cloud":
        assert [f.datatype for f in got.field] == [6, 3]
        assert got.is_dense
    else:
        assert (got.angular.x, got.angular.y, got.angular.z) == (-4.5, 5.75, -6.875)


def test_gazebo_to_ros_image_from_the_real_peer(
    bridge: RunningBridge, ros_side: RosSide, started: list[PeerProcess]
) -> None:
    topic = bridge.topics.image_to_ros
    wait_until(lambda: ros_side.count_publishers(topic) >= 1, WAIT, f"a publisher on {topic}")
    inbox, _ = ros_side.subscribe(Image, topic)
    size = WIDTH * HEIGHT * 3
    peer = start_peer(
        "pub", topic, "ignition.msgs.Image", "50", "10", rgb_text_proto(WIDTH, HEIGHT, "a::b"),
        "--bytes", str(size), "--wire-type", GZ_IMAGE, "--wait", str(WAIT),
    )  # fmt: skip
    started.append(peer)
    wait_until(lambda: bool(inbox.items()), WAIT, "an image in rclpy")
    msg = inbox.items()[0][0]
    assert (msg.width, msg.height, msg.step) == (WIDTH, HEIGHT, WIDTH * 3)
    assert (msg.encoding, msg.is_bigendian, msg.header.frame_id) == ("rgb8", 0, "a/b")
    assert bytes(msg.data) == pattern_bytes(size)
    # The delivery threads of the two bulk channels (image, cloud) lowered their own priority
    # when they started, by the default BULK_THREAD_NICE, and the libzmq I/O thread that reads
    # their frames follows them (bulk_context.py); no other thread did.
    bulk = VARIANTS[bridge.variant].get(BULK_ENV) != "off"
    lowered = [f"{THREAD_NAME_PREFIX}/ZMQbg/IO/0", "gz-sub", "gz-sub"] if bulk else []
    assert lowered_threads(bridge.process.pid) == [(name, BULK_THREAD_NICE) for name in lowered]


def test_gazebo_to_ros_camera_frame_from_the_real_peer(
    bridge: RunningBridge, ros_side: RosSide, started: list[PeerProcess]
) -> None:
    """A frame of 230 KB (the reader hands frames from 64 KiB on as writable views) with a
    gz-sensors camera's header: its CDR is built in the frame (``bulk/path.py`` ``in_place``)."""
    topic = bridge.topics.image_to_ros
    width, height = 320, 240
    size = width * height * 3
    text = rgb_text_proto(width, height, "robot::camera", seq="4711")
    frame = parse_gz("Image", text)
    frame.data = pattern_bytes(size)
    assert IMAGE.bulk is not None
    own = memoryview(bytearray(frame.SerializeToString()))
    assert isinstance(gz_to_ros_cdr(IMAGE.bulk, type(frame), own), memoryview)
    wait_until(lambda: ros_side.count_publishers(topic) >= 1, WAIT, f"a publisher on {topic}")
    inbox, _ = ros_side.subscribe(Image, topic)
    peer = start_peer(
        "pub", topic, "ignition.msgs.Image", "50", "50", text, "--bytes", str(size),
        "--wire-type", GZ_IMAGE, "--wait", str(WAIT),
    )  # fmt: skip
    started.append(peer)

    def frames() -> list[Any]:
        return [msg for msg, _ in inbox.items() if msg.width == width]

    wait_until(lambda: bool(frames()), WAIT, "a camera frame in rclpy")
    for msg in frames():
        assert (msg.width, msg.height, msg.step, msg.encoding) == (width, height, width * 3, "rgb8")
        assert (msg.header.stamp.sec, msg.header.stamp.nanosec) == (812, 4_000_000)
        assert msg.header.frame_id == "robot/camera"
        assert bytes(msg.data) == pattern_bytes(size)


def test_only_fast_dds_event_threads_are_batched(bridge: RunningBridge) -> None:
    """Fast DDS's event thread runs under SCHED_BATCH once the bridge serves (so its wake-ups
    do not preempt the thread writing a message), unless switched off; no other thread does."""
    expected = set() if VARIANTS[bridge.variant].get(DDS_EVENT_BATCH_ENV) == "off" else {"dds.ev"}
    wait_until(
        lambda: batched_thread_names(bridge.process.pid) == expected,
        WAIT,
        f"SCHED_BATCH on exactly {expected or 'no thread'}",
    )


def batched_thread_names(pid: int) -> set[str]:
    """The names (up to the last dot) of ``pid``'s threads under SCHED_BATCH."""
    names = set()
    for tid in os.listdir(f"/proc/{pid}/task"):
        with contextlib.suppress(OSError):
            if os.sched_getscheduler(int(tid)) == os.SCHED_BATCH:
                with open(f"/proc/{pid}/task/{tid}/comm", encoding="utf-8") as comm:
                    names.add(comm.read().strip().rsplit(".", 1)[0])
    return names


def lowered_threads(pid: int) -> list[tuple[str, int]]:
    """The names (up to a space: ``gz-sub <topic>`` is ``gz-sub``) and nice values of
    ``pid``'s threads whose nice value is not 0 (field 19 of /proc/.../stat), sorted."""
    found = []
    for tid in os.listdir(f"/proc/{pid}/task"):
        with open(f"/proc/{pid}/task/{tid}/stat", encoding="ascii") as stat:
            name, rest = stat.read().split("(", 1)[1].rsplit(")", 1)
        nice = int(rest.split()[16])
        if nice:
            found.append((name.split(" ")[0], nice))
    return sorted(found)


def test_gazebo_to_ros_cloud(bridge: RunningBridge, ros_side: RosSide, gz_node: GzNode) -> None:
    topic = bridge.topics.cloud_to_ros
    wait_until(lambda: ros_side.count_publishers(topic) >= 1, WAIT, f"a publisher on {topic}")
    inbox, _ = ros_side.subscribe(PointCloud2, topic)
    pair = default_registry().get("sensor_msgs/msg/PointCloud2", GZ_CLOUD)
    sent = pair.to_gz(ros_cloud(5))
    rest = type(sent)()
    rest.CopyFrom(sent)
    rest.ClearField("data")
    # The data field first: the bulk path must find it wherever it is in the payload.
    payload = bytes([8 << 3 | 2, len(sent.data)]) + sent.data + rest.SerializeToString()
    assert type(sent).FromString(payload) == sent
    publisher = gz_node.advertise(topic, GZ_CLOUD)
    publish_until(lambda _i: publisher.publish_raw(payload), lambda: bool(inbox.items()), "cloud")
    assert inbox.items()[0][0] == ros_cloud(5)


def bad_ros_image(index: int) -> Image:
    """Rows that overlap: a step one byte short of width * 3."""
    msg = ros_image(index)
    msg.step = WIDTH * 3 - 1
    return msg


def bad_ros_cloud(index: int) -> PointCloud2:
    """The cloud of issue 14: width 4294967295 over 30 bytes of data."""
    msg = ros_cloud(index)
    msg.width = 4_294_967_295
    return msg


#: What the bridge logs for each bad message, on every path.
BAD_ROS_ERRORS = {
    "image": "sensor_msgs/msg/Image step is 17, less than width*bytes_per_pixel = 6*3 = 18 "
    "for 6x4 bgr8",
    "cloud": "sensor_msgs/msg/PointCloud2 sizes do not match its data: row_step is 30, less "
    "than width*point_step = 4294967295*6 = 25769803770",
}


@pytest.mark.parametrize("kind", ["image", "cloud"])
def test_ros_to_gazebo_inconsistent_sizes_are_never_forwarded(
    bridge: RunningBridge, ros_side: RosSide, started: list[PeerProcess], kind: str
) -> None:
    """Bad and good messages alternate; the echo gets only good ones, the log names the bad."""
    good, bad, type_name, ros_type, gz_type, topic = {
        "image": (ros_image, bad_ros_image, "Image", "sensor_msgs/msg/Image", GZ_IMAGE,
                  bridge.topics.image_to_gz),
        "cloud": (ros_cloud, bad_ros_cloud, "PointCloudPacked", "sensor_msgs/msg/PointCloud2",
                  GZ_CLOUD, bridge.topics.cloud_to_gz),
    }[kind]  # fmt: skip
    pair = default_registry().get(ros_type, gz_type)
    with pytest.raises(ConversionError) as object_error:
        pair.to_gz(bad(0))
    assert str(object_error.value) == BAD_ROS_ERRORS[kind]
    echo = _echo(topic, type_name, count=3)
    started.append(echo)
    publisher = ros_side.run(lambda: ros_side.node.create_publisher(type(good(0)), topic, 10))
    sent: list[Any] = []

    def publish(index: int) -> None:
        sent.append(good(100 + index))
        ros_side.run(lambda: (publisher.publish(bad(index)), publisher.publish(sent[-1])))

    publish_until(publish, lambda: len(_messages(echo, type_name)) >= 3, f"3 good {kind}s")
    expected = [pair.to_gz(msg) for msg in sent]
    assert all(got in expected for got in _messages(echo, type_name))
    wait_until(lambda: BAD_ROS_ERRORS[kind] in bridge.process.output(), WAIT, "the error logged")


def bad_gz_payload(kind: str, index: int) -> bytes:
    """A Gazebo image one byte short, or a cloud 4294967295 points wide."""
    if kind == "image":
        frame = rgb_frame(WIDTH, HEIGHT, data=bytes(WIDTH * HEIGHT * 3 - 1))
        frame.header.stamp.sec = index
        return bytes(frame.SerializeToString())
    cloud = default_registry().get("sensor_msgs/msg/PointCloud2", GZ_CLOUD).to_gz(ros_cloud(index))
    cloud.width = 4_294_967_295
    return bytes(cloud.SerializeToString())


BAD_GZ_ERRORS = {
    "image": "gz.msgs.Image data has 71 bytes, fewer than height*step = 4*18 = 72 for 6x4 "
    "rgb8 (step = width*bytes_per_pixel; the gz step is ignored)",
    "cloud": "gz.msgs.PointCloudPacked sizes do not match its data: row_step is 30, less "
    "than width*point_step = 4294967295*6 = 25769803770",
}


@pytest.mark.parametrize("kind", ["image", "cloud"])
def test_gazebo_to_ros_inconsistent_sizes_are_never_forwarded(
    bridge: RunningBridge, ros_side: RosSide, gz_node: GzNode, kind: str
) -> None:
    """Bad and good messages alternate; rclpy gets only good ones, the log names the bad."""
    msg_type, ros_type, gz_type, topic = {
        "image": (Image, "sensor_msgs/msg/Image", GZ_IMAGE, bridge.topics.image_to_ros),
        "cloud": (PointCloud2, "sensor_msgs/msg/PointCloud2", GZ_CLOUD,
                  bridge.topics.cloud_to_ros),
    }[kind]  # fmt: skip
    pair = default_registry().get(ros_type, gz_type)
    gz_class = message_class(gz_type)
    with pytest.raises(ConversionError) as object_error:
        pair.to_ros(gz_class.FromString(bad_gz_payload(kind, 0)))
    assert str(object_error.value) == BAD_GZ_ERRORS[kind]
    wait_until(lambda: ros_side.count_publishers(topic) >= 1, WAIT, f"a publisher on {topic}")
    inbox, _ = ros_side.subscribe(msg_type, topic)
    publisher = gz_node.advertise(topic, gz_type)
    sent: list[Any] = []

    def publish(index: int) -> None:
        if kind == "image":
            sent.append(rgb_frame(WIDTH, HEIGHT, frame_id=f"cam{index}"))
        else:
            sent.append(pair.to_gz(ros_cloud(100 + index)))
        publisher.publish_raw(bad_gz_payload(kind, index))
        publisher.publish_raw(sent[-1].SerializeToString())

    publish_until(publish, lambda: len(inbox.items()) >= 3, f"3 good {kind}s in rclpy")
    expected = [pair.to_ros(msg) for msg in sent]
    assert all(got in expected for got, _ in inbox.items())
    wait_until(lambda: BAD_GZ_ERRORS[kind] in bridge.process.output(), WAIT, "the error logged")

"""Channels in one process: messages converted both ways, loop prevention, Gazebo spellings.

The bridge runs on a memory Gazebo node; other memory nodes on its network play Gazebo
processes (``native=Spelling.IGNITION``: a Fortress one, which announces and takes only
``ignition.msgs.*``, docs/protocol-lines.md §9). The ROS side is an rclpy node of the same process.
"""

from __future__ import annotations

import time
from collections import Counter
from typing import Any

import pytest
from geometry_msgs.msg import PoseStamped, Twist
from sensor_msgs.msg import Imu
from std_msgs.msg import String

from ros_gz_bridge_py.config import Direction, TopicBridgeSpec
from ros_gz_bridge_py.core.channel import ChannelState
from ros_gz_bridge_py.msgs import message_class
from ros_gz_bridge_py.msgs.names import Spelling
from tests.core.harness import (
    Inbox,
    Rig,
    RosWorld,
    gz_to_ros,
    options,
    publish_until,
    ros_to_gz,
    settled,
    unique,
    wait_until,
)

pytestmark = [pytest.mark.ros]  # rclpy participants, in this process

STRING, IGN_STRING = "gz.msgs.StringMsg", "ignition.msgs.StringMsg"
GzString = message_class(STRING)
GzTwist = message_class("gz.msgs.Twist")
GzPose = message_class("gz.msgs.Pose")
GzImu = message_class("gz.msgs.IMU")
FortressImu = message_class("ignition.msgs.IMU")
BATCH = 10


def string_spec(topic: str, direction: Direction, gz_type: str = STRING) -> TopicBridgeSpec:
    return TopicBridgeSpec(topic, topic, "std_msgs/msg/String", gz_type, direction)


def twist(index: int) -> Any:
    """A ROS Twist whose six values all differ (a swapped axis or sign shows)."""
    message = Twist()
    message.linear.x, message.linear.y, message.linear.z = index + 0.5, -2.0, 3.25
    message.angular.x, message.angular.y, message.angular.z = 0.125, index * -1.5, 7.0
    return message


def twist_values(message: Any) -> tuple[float, ...]:
    linear, angular = message.linear, message.angular
    return (linear.x, linear.y, linear.z, angular.x, angular.y, angular.z)


def test_gazebo_to_ros_converts_every_message(rig: Rig, world: RosWorld) -> None:
    topic = unique("g2r_twist")
    spec = TopicBridgeSpec(topic, topic, "geometry_msgs/msg/Twist", "gz.msgs.Twist",
                           Direction.GZ_TO_ROS)  # fmt: skip
    channel = gz_to_ros(rig.add(spec))
    publisher = rig.gazebo().advertise(topic, "gz.msgs.Twist")
    assert publisher.has_connections()  # the bridge subscribed at once: it is not lazy
    inbox, _ = world.subscribe(Twist, topic)

    def publish(index: int) -> None:
        gz = GzTwist()
        ros = twist(index)
        gz.linear.x, gz.linear.y, gz.linear.z = ros.linear.x, ros.linear.y, ros.linear.z
        gz.angular.x, gz.angular.y, gz.angular.z = ros.angular.x, ros.angular.y, ros.angular.z
        publisher.publish(gz)

    warm = publish_until(lambda i: publish(1000 + i), lambda: bool(inbox.messages()), "a Twist")
    for index in range(BATCH):
        publish(index)
    settled(channel, warm + BATCH)
    received = inbox.wait_for(lambda got: len(got) >= warm + BATCH, "the batch in ROS")
    batch = [twist_values(m) for m in received if m.linear.x < 1000]
    assert batch == [twist_values(twist(index)) for index in range(BATCH)]
    assert (channel.stats.published, channel.stats.conversion_errors) == (warm + BATCH, 0)


@pytest.mark.parametrize("light_read", [True, False], ids=["light-read", "rclpy-objects"])
def test_ros_to_gazebo_converts_every_message(
    make_rig: Any, world: RosWorld, light_read: bool
) -> None:
    rig: Rig = make_rig(options(light_read=light_read))
    topic = unique("r2g_twist")
    spec = TopicBridgeSpec(topic, topic, "geometry_msgs/msg/Twist", "gz.msgs.Twist",
                           Direction.ROS_TO_GZ)  # fmt: skip
    channel = ros_to_gz(rig.add(spec))
    inbox = Inbox()
    rig.gazebo().subscribe_typed(topic, GzTwist, inbox)
    publisher = world.publisher(Twist, topic)
    warm = publish_until(
        lambda i: publisher.publish(twist(1000 + i)), lambda: bool(inbox.messages()), "a Twist"
    )
    for index in range(BATCH):
        publisher.publish(twist(index))
    settled(channel, warm + BATCH)
    received = inbox.wait_for(lambda got: len(got) == warm + BATCH, "the batch in Gazebo")
    batch = [twist_values(m) for m in received if m.linear.x < 1000]
    assert batch == [twist_values(twist(index)) for index in range(BATCH)]
    assert {info.msg_type for info in inbox.infos()} == {"gz.msgs.Twist"}


def test_bidirectional_bridge_carries_each_message_once_and_never_back(
    rig: Rig, world: RosWorld
) -> None:
    """Both sides publish and subscribe the topic; each message crosses once. The bridge's
    counters prove it: its ROS subscription skipped exactly what it published to ROS, and
    its Gazebo subscription received exactly what Gazebo published."""
    topic = unique("chat")
    handle = rig.add(string_spec(topic, Direction.BIDIRECTIONAL))
    to_ros, to_gz = gz_to_ros(handle), ros_to_gz(handle)
    assert to_gz.loop_guard
    gazebo = rig.gazebo()
    gz_inbox = Inbox()
    gazebo.subscribe_typed(topic, GzString, gz_inbox, ignore_local=True)
    gz_publisher = gazebo.advertise(topic, STRING)
    ros_inbox, _ = world.subscribe(String, topic)
    ros_publisher = world.publisher(String, topic)

    def ros_data() -> list[str]:
        return [m.data for m in ros_inbox.messages()]

    def gz_data() -> list[str]:
        return [m.data for m in gz_inbox.messages()]

    # One side at a time, each settled before the next: the loop guard tells the bridge's own
    # samples by sequence number and write time, and this keeps the test's writes apart.
    gz_warm = publish_until(
        lambda i: gz_publisher.publish(GzString(data=f"warm gz {i}")),
        lambda: any(d.startswith("warm gz") for d in ros_data()),
        "Gazebo -> ROS",
    )
    settled(to_ros, gz_warm)
    wait_until(lambda: to_gz.stats.own_skipped == gz_warm, "the warm-up skipped as own")
    ros_warm = publish_until(
        lambda i: ros_publisher.publish(String(data=f"warm ros {i}")),
        lambda: any(d.startswith("warm ros") for d in gz_data()),
        "ROS -> Gazebo",
    )
    settled(to_gz, ros_warm)

    from_gz = [f"gz {index}" for index in range(BATCH)]
    from_ros = [f"ros {index}" for index in range(BATCH)]
    for text in from_gz:
        gz_publisher.publish(GzString(data=text))
    settled(to_ros, gz_warm + BATCH)
    wait_until(lambda: to_gz.stats.own_skipped == gz_warm + BATCH, "the batch skipped as own")
    for text in from_ros:
        ros_publisher.publish(String(data=text))
    settled(to_gz, ros_warm + BATCH)
    ros_inbox.wait_for(
        lambda got: (
            Counter(m.data for m in got if not m.data.startswith("warm"))
            == Counter(from_gz + from_ros)
        ),
        "each message once in ROS",
    )

    # Gazebo got ROS's messages once each and none of its own back.
    assert Counter(d for d in gz_data() if not d.startswith("warm")) == Counter(from_ros)
    assert not any(d.startswith("warm gz") for d in gz_data())
    # The bridge's Gazebo side received only what Gazebo published, its ROS side only ROS's.
    assert to_ros.stats.received == gz_warm + BATCH
    assert to_gz.stats.received == ros_warm + BATCH
    assert to_gz.stats.own_skipped == to_ros.stats.published == gz_warm + BATCH


@pytest.mark.parametrize("configured", [STRING, IGN_STRING])
def test_fortress_publisher_is_read_under_either_spelling(
    rig: Rig, world: RosWorld, configured: str
) -> None:
    topic = unique("fortress_pub")
    channel = gz_to_ros(rig.add(string_spec(topic, Direction.GZ_TO_ROS, configured)))
    fortress = rig.gazebo(native=Spelling.IGNITION)
    publisher = fortress.advertise(topic, IGN_STRING)
    assert [info.msg_type for info in rig.gz.topic_info(topic)] == [IGN_STRING]
    assert publisher.has_connections()
    inbox, _ = world.subscribe(String, topic)
    warm = publish_until(
        lambda i: publisher.publish(GzString(data=f"from fortress {i}")),
        lambda: bool(inbox.messages()),
        "a Fortress message in ROS",
    )
    settled(channel, warm)
    assert inbox.messages()[0].data.startswith("from fortress ")
    assert channel.stats.conversion_errors == 0


@pytest.mark.parametrize("configured", [STRING, IGN_STRING])
def test_each_gazebo_line_gets_each_message_once_in_its_spelling(
    rig: Rig, world: RosWorld, configured: str
) -> None:
    """A Fortress and a Harmonic subscriber on one topic, and a generic Fortress one."""
    topic = unique("lines_sub")
    channel = ros_to_gz(rig.add(string_spec(topic, Direction.ROS_TO_GZ, configured)))
    fortress, harmonic, recorder = Inbox(), Inbox(), Inbox()
    rig.gazebo(native=Spelling.IGNITION).subscribe(topic, fortress, IGN_STRING)
    rig.gazebo(native=Spelling.GZ).subscribe(topic, harmonic, STRING)
    rig.gazebo(native=Spelling.IGNITION).subscribe(topic, recorder)  # like `ign topic -e`
    publisher = world.publisher(String, topic)
    warm = publish_until(
        lambda i: publisher.publish(String(data=f"warm {i}")),
        lambda: bool(fortress.messages() and harmonic.messages() and recorder.messages()),
        "every Gazebo subscriber receives",
    )
    settled(channel, warm)
    for index in range(BATCH):
        publisher.publish(String(data=f"to gazebo {index}"))
    settled(channel, warm + BATCH)

    expected = [f"to gazebo {index}" for index in range(BATCH)]
    for inbox, spelling in ((fortress, IGN_STRING), (harmonic, STRING), (recorder, IGN_STRING)):
        texts = [GzString.FromString(payload).data for payload in inbox.messages()]
        assert [t for t in texts if t.startswith("to gazebo")] == expected
        assert len(texts) == warm + BATCH  # once each, never twice
        assert {info.msg_type for info in inbox.infos()} == {spelling}


def fortress_imu(stamp: int) -> Any:
    imu = FortressImu()
    imu.header.stamp.sec = stamp
    imu.orientation.w = 1.0
    imu.angular_velocity.x, imu.angular_velocity.y, imu.angular_velocity.z = 0.5, -0.25, 2.0
    imu.linear_acceleration.x, imu.linear_acceleration.z = 1.5, 9.75
    return imu


def harmonic_imu(stamp: int) -> Any:
    imu = GzImu()
    imu.header.stamp.sec = stamp
    imu.orientation.w = 1.0
    imu.angular_velocity.x, imu.angular_velocity.y, imu.angular_velocity.z = 4.0, 5.0, 6.0
    imu.linear_acceleration.x, imu.linear_acceleration.z = -1.0, 8.5
    imu.orientation_covariance.data.extend([0.5] * 9)
    imu.angular_velocity_covariance.data.extend([0.25] * 9)
    imu.linear_acceleration_covariance.data.extend([0.125] * 9)
    return imu


def vector(value: Any) -> tuple[float, float, float]:
    return (value.x, value.y, value.z)


def test_imu_is_read_in_the_layout_of_its_gazebo_line(rig: Rig, world: RosWorld) -> None:
    """One topic, a Fortress and a Harmonic IMU publisher: each message in its own layout
    (the Fortress layout has angular velocity where Harmonic has a covariance)."""
    topic = unique("imu")
    spec = TopicBridgeSpec(topic, topic, "sensor_msgs/msg/Imu", "gz.msgs.IMU",
                           Direction.GZ_TO_ROS)  # fmt: skip
    channel = gz_to_ros(rig.add(spec))
    fortress = rig.gazebo(native=Spelling.IGNITION).advertise(topic, "ignition.msgs.IMU")
    harmonic = rig.gazebo(native=Spelling.GZ).advertise(topic, "gz.msgs.IMU")
    inbox, _ = world.subscribe(Imu, topic)

    def both(index: int) -> None:
        fortress.publish(fortress_imu(100 + index))
        harmonic.publish(harmonic_imu(200 + index))

    def arrived(got: list[Any]) -> bool:
        return {m.header.stamp.sec // 100 for m in got} == {1, 2}

    sent = publish_until(both, lambda: arrived(inbox.messages()), "both IMUs in ROS")
    settled(channel, 2 * sent)
    assert channel.stats.conversion_errors == 0
    received = inbox.messages()
    from_fortress = next(m for m in received if m.header.stamp.sec // 100 == 1)
    from_harmonic = next(m for m in received if m.header.stamp.sec // 100 == 2)
    assert vector(from_fortress.angular_velocity) == (0.5, -0.25, 2.0)
    assert vector(from_fortress.linear_acceleration) == (1.5, 0.0, 9.75)
    assert list(from_fortress.angular_velocity_covariance) == [0.0] * 9
    assert from_fortress.orientation.w == 1.0
    assert vector(from_harmonic.angular_velocity) == (4.0, 5.0, 6.0)
    assert vector(from_harmonic.linear_acceleration) == (-1.0, 0.0, 8.5)
    assert list(from_harmonic.orientation_covariance) == [0.5] * 9
    assert list(from_harmonic.linear_acceleration_covariance) == [0.125] * 9


def test_imu_to_gazebo_is_written_in_each_subscriber_layout(rig: Rig, world: RosWorld) -> None:
    topic = unique("imu_out")
    spec = TopicBridgeSpec(topic, topic, "sensor_msgs/msg/Imu", "gz.msgs.IMU",
                           Direction.ROS_TO_GZ)  # fmt: skip
    channel = ros_to_gz(rig.add(spec))
    fortress, harmonic = Inbox(), Inbox()
    rig.gazebo(native=Spelling.IGNITION).subscribe_typed(topic, FortressImu, fortress)
    rig.gazebo(native=Spelling.GZ).subscribe_typed(topic, GzImu, harmonic)
    publisher = world.publisher(Imu, topic)
    ros = Imu()
    ros.angular_velocity.x, ros.angular_velocity.y, ros.angular_velocity.z = 1.0, 2.0, 3.0
    ros.linear_acceleration.z = 9.5
    ros.angular_velocity_covariance = [0.25] * 9
    sent = publish_until(
        lambda _: publisher.publish(ros),
        lambda: bool(fortress.messages() and harmonic.messages()),
        "both Gazebo lines receive",
    )
    settled(channel, sent)
    assert channel.stats.conversion_errors == 0
    for inbox in (fortress, harmonic):
        message = inbox.messages()[0]
        assert vector(message.angular_velocity) == (1.0, 2.0, 3.0)
        assert vector(message.linear_acceleration) == (0.0, 0.0, 9.5)
    assert list(harmonic.messages()[0].angular_velocity_covariance.data) == [0.25] * 9


@pytest.mark.parametrize(
    ("entry_frame", "expected_frame"), [(None, "node_frame"), ("entry_frame", "entry_frame")]
)
def test_headers_are_rewritten_as_configured(
    make_rig: Any, world: RosWorld, entry_frame: str | None, expected_frame: str
) -> None:
    rig: Rig = make_rig(
        options(override_frame_id="node_frame", override_timestamps_with_wall_time=True)
    )
    topic = unique("frames")
    spec = TopicBridgeSpec(topic, topic, "geometry_msgs/msg/PoseStamped", "gz.msgs.Pose",
                           Direction.GZ_TO_ROS, frame_id=entry_frame)  # fmt: skip
    rig.add(spec)
    publisher = rig.gazebo().advertise(topic, "gz.msgs.Pose")
    pose = GzPose()
    pose.header.stamp.sec = 5
    pose.header.data.add(key="frame_id", value=["gz_frame"])
    pose.position.x = 2.5
    inbox, _ = world.subscribe(PoseStamped, topic)
    publish_until(lambda _: publisher.publish(pose), lambda: bool(inbox.messages()), "a pose")
    received = inbox.messages()[0]
    assert received.pose.position.x == 2.5
    assert received.header.frame_id == expected_frame
    stamp = received.header.stamp.sec + received.header.stamp.nanosec / 1e9
    assert abs(stamp - time.time()) < 60, "the stamp is not wall time (Gazebo said 5 s)"


def test_a_removed_bridge_leaves_nothing_open(rig: Rig, world: RosWorld) -> None:
    topic = unique("removed")
    gazebo = rig.gazebo()
    publisher = gazebo.advertise(topic, STRING)
    handle = rig.add(string_spec(topic, Direction.BIDIRECTIONAL))
    assert publisher.has_connections()
    assert {info.process_uuid for info in gazebo.topic_info(topic)} == {
        gazebo.process_uuid,
        rig.gz.process_uuid,
    }
    wait_until(lambda: len(world.publishers(topic)) == 1, "the bridge's ROS publisher")
    wait_until(lambda: len(world.subscribers(topic)) == 1, "the bridge's ROS subscription")

    rig.remove(handle)
    assert handle not in rig.bridge.handles
    assert [channel.state for channel in handle.channels] == [ChannelState.CLOSED] * 2
    assert not publisher.has_connections()
    assert {info.process_uuid for info in gazebo.topic_info(topic)} == {gazebo.process_uuid}
    wait_until(lambda: not world.publishers(topic), "the ROS publisher gone")
    wait_until(lambda: not world.subscribers(topic), "the ROS subscription gone")
    rig.remove(handle)  # twice is harmless


@pytest.mark.parametrize(("max_queued_bytes", "dropping"), [(3_000_000, True), (64 << 20, False)])
def test_max_queued_bytes_bounds_each_channel_queue(
    make_rig: Any, max_queued_bytes: int, dropping: bool
) -> None:
    """50 serialized messages of 1 MB handed over at once (microseconds each, against a
    millisecond to convert and publish one): a bridge whose queues hold 3 MB drops some,
    counted in the channel's drops; with the default 64 MiB none is dropped (before
    ``max_queued_bytes``, every bridge took all 50)."""
    rig: Rig = make_rig(options(max_queued_bytes=max_queued_bytes))
    topic = unique("bytes")
    spec = TopicBridgeSpec(topic, topic, "std_msgs/msg/String", "gz.msgs.StringMsg",
                           Direction.GZ_TO_ROS)  # fmt: skip
    channel = gz_to_ros(rig.add(spec))
    publisher = rig.gazebo().advertise(topic, "gz.msgs.StringMsg")
    payload = message_class("gz.msgs.StringMsg")(data="x" * 1_000_000).SerializeToString()
    for _ in range(50):
        publisher.publish_raw(payload)
    wait_until(
        lambda: channel.stats.published + channel.dropped == 50,
        "all 50 published or dropped",
    )
    assert (channel.dropped > 0) == dropping, channel.dropped

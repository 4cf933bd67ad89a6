"""Status in one process: StatusTracker counts and rates, levels, ``/diagnostics``, the table.

Rates are computed over the time between two snapshots, so the tracker gets a clock the test
moves: a rate is then an exact number, not a timing. Counters are checked against exactly what
the test sent, once the channel has handled every message (``settled``).
"""

from __future__ import annotations

import dataclasses
import io
import os
import signal
import threading
from typing import Any

import pytest
from diagnostic_msgs.msg import DiagnosticArray
from sensor_msgs.msg import Image
from std_msgs.msg import String

from ros_gz_bridge_py.config import Direction, ServiceBridgeSpec, TopicBridgeSpec
from ros_gz_bridge_py.converters.registry import Pair, Registry
from ros_gz_bridge_py.core.channel import MIN_DELIVERY_QUEUE
from ros_gz_bridge_py.core.status import (
    OK,
    STALE,
    WARN,
    ChannelStatus,
    DiagnosticsPublisher,
    StatusTracker,
    diagnostic_array,
    format_table,
    start_diagnostics,
    table_on_signal,
)
from ros_gz_bridge_py.msgs import message_class
from tests.core.harness import (
    WAIT,
    Rig,
    RosWorld,
    gz_to_ros,
    publish_until,
    ros_to_gz,
    settled,
    unique,
    wait_until,
)

pytestmark = [pytest.mark.ros]  # rclpy participants, in this process

STRING = "gz.msgs.StringMsg"
GzString = message_class(STRING)
GzImage = message_class("gz.msgs.Image")
#: gz PixelFormatType RGB_INT8; 0 (UNKNOWN_PIXEL_FORMAT) has no ROS encoding.
RGB_INT8, UNKNOWN_PIXEL_FORMAT = 3, 0


class FakeClock:
    """A monotonic clock that moves only when the test says so."""

    def __init__(self) -> None:
        self.now = 1000.0

    def __call__(self) -> float:
        return self.now

    def advance(self, seconds: float) -> None:
        self.now += seconds


def string_spec(topic: str, direction: Direction, **fields: Any) -> TopicBridgeSpec:
    return TopicBridgeSpec(topic, topic, "std_msgs/msg/String", STRING, direction, **fields)


def by_name(statuses: list[ChannelStatus]) -> dict[str, ChannelStatus]:
    return {status.name: status for status in statuses}


def warmed_up(rig: Rig, world: RosWorld, topic: str, channel: Any) -> tuple[Any, int]:
    """A Gazebo publisher of ``topic`` whose messages reach a ROS reader; how many it sent."""
    publisher = rig.gazebo().advertise(topic, STRING)
    inbox, _ = world.subscribe(String, topic)
    sent = publish_until(
        lambda i: publisher.publish(GzString(data=f"warm {i}")),
        lambda: bool(inbox.messages()),
        "a message in ROS",
    )
    settled(channel, sent)
    return publisher, sent


def test_snapshots_count_every_channel_with_rates_over_the_period(
    rig: Rig, world: RosWorld
) -> None:
    topic, idle, to_gz = unique("status"), unique("status_idle"), unique("status_to_gz")
    channel = gz_to_ros(rig.add(string_spec(topic, Direction.GZ_TO_ROS)))
    rig.add(string_spec(idle, Direction.GZ_TO_ROS, lazy=True))
    rig.add(string_spec(to_gz, Direction.ROS_TO_GZ))
    rig.add(ServiceBridgeSpec(unique("status_service"), "ros_gz_interfaces/srv/ControlWorld"))
    publisher, warm = warmed_up(rig, world, topic, channel)
    clock = FakeClock()
    tracker = StatusTracker(rig.bridge, now=clock)

    sent = 8
    for index in range(sent):
        publisher.publish(GzString(data=f"data {index}"))
    settled(channel, warm + sent)
    clock.advance(2.0)
    statuses = tracker.snapshot()
    assert [(s.direction, s.ros_name) for s in statuses[:3]] == [
        ("GZ->ROS", topic), ("GZ->ROS", idle), ("ROS->GZ", to_gz)
    ]  # fmt: skip
    assert statuses[3].direction == "service"
    assert statuses[3].gz_type == "gz.msgs.WorldControl/gz.msgs.Boolean"
    flowing = statuses[0]
    assert (flowing.received, flowing.published, flowing.errors, flowing.dropped) == (
        warm + sent, warm + sent, 0, 0
    )  # fmt: skip
    assert flowing.rate == (warm + sent) / 2.0  # the first period counts from zero
    assert (flowing.level, flowing.message(), flowing.state) == (OK, "ok", "active")
    lazy = statuses[1]
    assert (lazy.level, lazy.state) == (STALE, "lazy_idle")
    assert lazy.message() == "lazy: no subscribers, input side closed"
    assert statuses[2].level == OK

    for index in range(6):
        publisher.publish(GzString(data=f"more {index}"))
    settled(channel, warm + sent + 6)
    clock.advance(4.0)
    again = tracker.snapshot()[0]
    assert (again.received, again.rate, again.new_problems) == (warm + sent + 6, 1.5, 0)
    clock.advance(1.0)
    assert tracker.snapshot()[0].rate == 0.0


def gz_image(height: int, pixel_format: int) -> Any:
    image = GzImage(width=2, height=height, step=6, pixel_format_type=pixel_format)
    image.data = bytes(6 * height)
    return image


def test_conversion_errors_are_counted_and_warn_for_one_period(rig: Rig, world: RosWorld) -> None:
    topic = unique("status_image")
    spec = TopicBridgeSpec(topic, topic, "sensor_msgs/msg/Image", "gz.msgs.Image",
                           Direction.GZ_TO_ROS)  # fmt: skip
    channel = gz_to_ros(rig.add(spec))
    assert channel.bulk is not None  # images take the bulk path
    publisher = rig.gazebo().advertise(topic, "gz.msgs.Image")
    inbox, _ = world.subscribe(Image, topic)
    warm = publish_until(
        lambda _: publisher.publish(gz_image(1, RGB_INT8)),
        lambda: bool(inbox.messages()),
        "an image in ROS",
    )
    settled(channel, warm)
    clock = FakeClock()
    tracker = StatusTracker(rig.bridge, now=clock)
    tracker.snapshot()

    bad, good = 2, 3
    for _ in range(bad):
        publisher.publish(gz_image(2, UNKNOWN_PIXEL_FORMAT))
    for _ in range(good):
        publisher.publish(gz_image(2, RGB_INT8))
    settled(channel, warm + bad + good)
    inbox.wait_for(lambda got: sum(m.height == 2 for m in got) == good, "the good images")
    clock.advance(1.0)
    status = tracker.snapshot()[0]
    assert (status.received, status.published, status.errors) == (warm + 5, warm + 3, 2)
    assert (status.new_problems, status.level) == (2, WARN)
    assert "pixel_format_type 0 (UNKNOWN_PIXEL_FORMAT) has no ROS encoding" in status.last_error
    assert status.message().startswith("2 errors/drops in the last period: gz.msgs.Image")
    clock.advance(1.0)
    calm = tracker.snapshot()[0]
    assert (calm.errors, calm.new_problems, calm.level) == (2, 0, OK)


def test_an_undecodable_payload_is_a_conversion_error(rig: Rig) -> None:
    topic = unique("status_garbage")
    channel = gz_to_ros(rig.add(string_spec(topic, Direction.GZ_TO_ROS)))
    publisher = rig.gazebo().advertise(topic, STRING)
    publisher.publish_raw(b"\xff\xff\xff")  # not a protobuf message
    publisher.publish(GzString(data="fine"))
    settled(channel, 2)
    assert (channel.stats.conversion_errors, channel.stats.published) == (1, 1)
    assert channel.stats.last_error.startswith(f"undecodable {STRING} payload of 3 bytes")


def blocking_registry(release: threading.Event, holding: threading.Event) -> Registry:
    """String <-> StringMsg whose conversion to ROS waits for ``release`` (after the first
    message says it is ``holding``), so the test controls when the delivery thread moves."""

    def to_ros(gz: Any) -> Any:
        holding.set()
        release.wait(WAIT)
        return String(data=gz.data)

    registry = Registry()
    registry.add(
        Pair("std_msgs/msg/String", STRING, lambda ros: GzString(data=ros.data), to_ros, String)
    )
    return registry


def test_queue_drops_are_counted(make_rig: Any) -> None:
    """The delivery thread holds one message; the queue keeps the newest MIN_DELIVERY_QUEUE
    of the rest and drops (and counts) exactly the older ones."""
    release, holding = threading.Event(), threading.Event()
    rig: Rig = make_rig(registry=blocking_registry(release, holding))
    topic = unique("status_drops")
    channel = gz_to_ros(rig.add(string_spec(topic, Direction.GZ_TO_ROS)))
    publisher = rig.gazebo().advertise(topic, STRING)
    clock = FakeClock()
    tracker = StatusTracker(rig.bridge, now=clock)
    try:
        publisher.publish(GzString(data="held"))
        assert holding.wait(WAIT)
        extra = 4
        for index in range(MIN_DELIVERY_QUEUE + extra):
            publisher.publish(GzString(data=str(index)))
        assert channel.dropped == extra
    finally:
        release.set()
    settled(channel, 1 + MIN_DELIVERY_QUEUE)
    clock.advance(1.0)
    status = tracker.snapshot()[0]
    assert (status.received, status.dropped, status.errors) == (1 + MIN_DELIVERY_QUEUE, extra, 0)
    assert (status.new_problems, status.level) == (extra, WARN)
    assert status.message() == f"{extra} errors/drops in the last period"


def test_ros_messages_the_native_loop_could_not_copy_are_drops(rig: Rig) -> None:
    """ROS -> Gazebo, the native loop counts the messages it had no memory to copy for the
    Python path (tests/unit/native/test_ros_pump_failed_copy.py) and tells the channel, whose
    DROPPED shows them (it showed 0 for every ROS -> Gazebo channel)."""
    channel = ros_to_gz(rig.add(string_spec(unique("status_lost"), Direction.ROS_TO_GZ)))
    clock = FakeClock()
    tracker = StatusTracker(rig.bridge, now=clock)
    tracker.snapshot()
    channel._lost(3)  # what RosChannelPump.turn calls with the loop's count
    clock.advance(1.0)
    status = tracker.snapshot()[0]
    assert (status.direction, status.dropped, status.errors) == ("ROS->GZ", 3, 0)
    assert (status.new_problems, status.level) == (3, WARN)


def test_diagnostic_array_carries_one_status_per_channel(rig: Rig) -> None:
    topic, idle = unique("diag"), unique("diag_idle")
    channel = gz_to_ros(rig.add(string_spec(topic, Direction.GZ_TO_ROS)))
    rig.add(string_spec(idle, Direction.GZ_TO_ROS, lazy=True))
    publisher = rig.gazebo().advertise(topic, STRING)
    clock = FakeClock()
    tracker = StatusTracker(rig.bridge, now=clock)
    for index in range(3):
        publisher.publish(GzString(data=str(index)))
    publisher.publish_raw(b"\xff")
    settled(channel, 4)
    clock.advance(0.5)
    stamp = rig.node.get_clock().now().to_msg()
    array = diagnostic_array(tracker.snapshot(), "/the_bridge", stamp)

    assert array.header.stamp == stamp
    entries = {entry.name: entry for entry in array.status}
    assert set(entries) == {f"ros_gz_bridge: GZ->ROS {topic}", f"ros_gz_bridge: GZ->ROS {idle}"}
    flowing = entries[f"ros_gz_bridge: GZ->ROS {topic}"]
    assert (flowing.level, flowing.hardware_id) == (WARN, "/the_bridge")
    values = {kv.key: kv.value for kv in flowing.values}
    assert values["received"] == "4"
    assert values["published"] == "3"
    assert values["conversion_errors"] == "1"
    assert values["dropped"] == "0"
    assert values["rate_hz"] == "8.00"
    assert values["state"] == "active"
    assert (values["ros_type"], values["gz_type"]) == ("std_msgs/msg/String", STRING)
    assert values["last_error"].startswith("undecodable")
    assert entries[f"ros_gz_bridge: GZ->ROS {idle}"].level == STALE


def test_diagnostics_are_published_on_their_topic(rig: Rig, world: RosWorld) -> None:
    topic = unique("diag_pub")
    channel = gz_to_ros(rig.add(string_spec(topic, Direction.GZ_TO_ROS)))
    publisher = rig.gazebo().advertise(topic, STRING)
    for index in range(5):
        publisher.publish(GzString(data=str(index)))
    settled(channel, 5)
    inbox, _ = world.subscribe(DiagnosticArray, "/diagnostics")
    hardware_id = rig.node.get_fully_qualified_name()
    diagnostics = world.run(lambda: DiagnosticsPublisher(rig.node, rig.bridge, 0.05))
    try:

        def ours(got: list[Any]) -> list[Any]:
            return [a for a in got if a.status and a.status[0].hardware_id == hardware_id]

        arrays = inbox.wait_for(lambda got: bool(ours(got)), "an array from the bridge")
        (status,) = ours(arrays)[0].status
        assert status.name == f"ros_gz_bridge: GZ->ROS {topic}"
        assert {kv.key: kv.value for kv in status.values}["received"] == "5"
    finally:
        world.run(diagnostics.close)


def test_start_diagnostics_takes_seconds_or_nothing(rig: Rig) -> None:
    for wrong in ("often", -1, True):
        assert start_diagnostics(rig.node, rig.bridge, wrong) is None
    assert start_diagnostics(rig.node, rig.bridge, 0) is None
    started = rig.world.run(lambda: start_diagnostics(rig.node, rig.bridge, 2))
    assert isinstance(started, DiagnosticsPublisher)
    rig.world.run(started.close)


def test_the_table_lists_every_channel_and_sigusr1_prints_it(rig: Rig) -> None:
    topic, to_gz = unique("table"), unique("table_to_gz")
    channel = gz_to_ros(rig.add(string_spec(topic, Direction.GZ_TO_ROS)))
    rig.add(string_spec(to_gz, Direction.ROS_TO_GZ))
    publisher = rig.gazebo().advertise(topic, STRING)
    for index in range(3):
        publisher.publish(GzString(data=str(index)))
    settled(channel, 3)
    table = format_table(StatusTracker(rig.bridge).snapshot())
    lines = table.splitlines()
    assert lines[0].split() == [
        "LEVEL", "DIRECTION", "ROS", "GAZEBO", "STATE", "IN", "OUT", "ERRORS", "DROPPED",
        "LIMITED", "RATE/s", "FLOW", "PATH",
    ]  # fmt: skip
    # The memory backend lets no native loop read: both channels convert in Python.
    assert [line.split()[-1] for line in lines[1:3]] == ["python", "python"]
    assert lines[1].split()[:8] == ["OK", "GZ->ROS", topic, topic, "active", "3", "3", "0"]
    assert lines[2].split()[:6] == ["OK", "ROS->GZ", to_gz, to_gz, "active", "0"]
    assert format_table([]).splitlines()[-1] == "(no bridges)"

    out = io.StringIO()
    with table_on_signal(rig.bridge, out=out):
        os.kill(os.getpid(), signal.SIGUSR1)
        wait_until(lambda: topic in out.getvalue(), "the table printed on SIGUSR1")
    printed = out.getvalue().splitlines()
    assert printed[0].split()[:3] == ["LEVEL", "DIRECTION", "ROS"]
    assert printed[1].split()[:7] == ["OK", "GZ->ROS", topic, topic, "active", "3", "3"]


def test_a_cause_of_several_channels_is_one_line_of_the_table() -> None:
    """The "no Gazebo process heard" cause was printed once per channel (eight ~300-character
    lines)."""
    quiet = ChannelStatus(
        "GZ->ROS", "/a", "/a", "std_msgs/msg/String", STRING, "active", 0, 0, 0, 0, 0.0, 0,
        why="no Gazebo process",
    )  # fmt: skip
    statuses = [quiet, dataclasses.replace(quiet, ros_name="/b"),
                dataclasses.replace(quiet, ros_name="/c", why="its own")]  # fmt: skip
    whys = [line for line in format_table(statuses).splitlines() if line.startswith("why")]
    assert whys == ["why 2 channels: no Gazebo process", "why GZ->ROS /c: its own"]

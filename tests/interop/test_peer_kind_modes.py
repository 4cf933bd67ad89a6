"""The C++ peer's benchmark modes (kind-pub, kind-sub, pub-fleet) against our node.

The benchmarks put these modes at the Gazebo end of every ZeroMQ flow, so the stamp they write
and read at a field path is what every latency figure rests on. Here our own node checks both:
what the real ign-transport publisher sends (the file's message, stamped with the send time),
and what the real subscriber reads back from messages we stamp.
"""

from __future__ import annotations

import re
import time
from pathlib import Path
from typing import Any

import pytest

from ros_gz_bridge_py.msgs import message_class
from testing.gzpeer import Inbox, start_peer, unique_name, wait_for_line, wait_until

pytestmark = pytest.mark.peer

NS = 1_000_000_000


def test_kind_pub_sends_the_file_message_stamped_at_the_path(
    ign_peer: Path, gz_node: Any, tmp_path: Path
) -> None:
    odometry = message_class("gz.msgs.Odometry")
    original = odometry()
    original.header.data.add(key="frame_id", value=["odom"])
    original.pose.position.x = 1.5
    original.twist.angular.z = -0.25
    message_file = tmp_path / "odometry.pb"
    message_file.write_bytes(original.SerializeToString())
    topic = unique_name("kind_pub")
    inbox = Inbox()
    gz_node.subscribe_typed(topic, odometry, inbox, msg_type="gz.msgs.Odometry")

    before = time.monotonic_ns()
    peer = start_peer(
        "kind-pub", topic, "ignition.msgs.Odometry", str(message_file), "0.5",
        "--hz", "40", "--stamp", "header.stamp", "--wire-type", "gz.msgs.Odometry",
    )  # fmt: skip
    sent = int(wait_for_line(peer, r"^SENT (\d+)", 15)[1])
    after = time.monotonic_ns()
    items = inbox.wait_for_count(sent, timeout=5)

    stamps = [msg.header.stamp.sec * NS + msg.header.stamp.nsec for msg, _ in items]
    assert len(stamps) == sent >= 10
    assert stamps == sorted(set(stamps))
    assert before < stamps[0]
    assert stamps[-1] < after
    for msg, info in items:
        assert info.msg_type == "gz.msgs.Odometry"
        msg.header.ClearField("stamp")
        assert msg == original


@pytest.mark.parametrize(
    ("gz_type", "path"),
    [("gz.msgs.Pose_V", "pose.0.header.stamp"), ("gz.msgs.Twist", "linear.x")],
)
def test_kind_sub_reads_the_stamp_we_write(
    ign_peer: Path, gz_node: Any, gz_type: str, path: str
) -> None:
    topic = unique_name("kind_sub")
    ignition_type = gz_type.replace("gz.msgs.", "ignition.msgs.")
    peer = start_peer(
        "kind-sub", topic, ignition_type, "20", "--count", "20", "--stamp", path,
        "--wire-type", gz_type,
    )  # fmt: skip
    wait_for_line(peer, r"^READY$")
    publisher = gz_node.advertise(topic, gz_type)
    wait_until(publisher.has_connections, 10, "the peer's subscription")
    time.sleep(0.3)  # its ZeroMQ connection comes up just after discovery
    msg = message_class(gz_type)()
    deadline = time.monotonic() + 15
    while peer.poll() is None and time.monotonic() < deadline:
        now = time.monotonic_ns()
        if gz_type == "gz.msgs.Twist":
            msg.linear.x = now / NS
        else:
            msg.ClearField("pose")
            msg.pose.add().header.stamp.sec, msg.pose[0].header.stamp.nsec = divmod(now, NS)
        publisher.publish(msg)
        time.sleep(0.02)

    stats = wait_for_line(peer, r"^STATS count=(\d+) .* median_us=([\d.]+) p99_us=([\d.]+)", 5)
    assert int(stats[1]) == 20
    # Latencies from our stamps: positive and far below a second on loopback.
    assert 0 < float(stats[2]) <= float(stats[3]) < 1_000_000


def test_kind_pub_rejects_a_stamp_path_the_type_lacks(ign_peer: Path, tmp_path: Path) -> None:
    message_file = tmp_path / "twist.pb"
    message_file.write_bytes(b"")
    peer = start_peer(
        "kind-pub", unique_name("bad_path"), "ignition.msgs.Twist", str(message_file), "1",
        "--stamp", "header.nonsense",
    )  # fmt: skip
    assert peer.wait(10) == 2
    assert "stamp path header.nonsense: no field nonsense" in peer.output()


def test_kind_pub_floods_a_second_topic_from_the_same_process(
    ign_peer: Path, gz_node: Any, tmp_path: Path
) -> None:
    clock, image = message_class("gz.msgs.Clock"), message_class("gz.msgs.Image")
    frame = image(width=4, height=2, data=bytes(range(24)))
    frame.header.data.add(key="frame_id", value=["camera"])
    (tmp_path / "clock.pb").write_bytes(b"")
    (tmp_path / "image.pb").write_bytes(frame.SerializeToString())
    clock_topic, image_topic = unique_name("kind_clock"), unique_name("kind_flood")
    clocks, images = Inbox(), Inbox()
    gz_node.subscribe_typed(clock_topic, clock, clocks, msg_type="gz.msgs.Clock")
    gz_node.subscribe_typed(image_topic, image, images, msg_type="gz.msgs.Image")

    peer = start_peer(
        "kind-pub", clock_topic, "ignition.msgs.Clock", str(tmp_path / "clock.pb"), "0.5",
        "--hz", "40", "--stamp", "sim", "--wire-type", "gz.msgs.Clock",
        "--flood", image_topic, "--flood-type", "ignition.msgs.Image",
        "--flood-file", str(tmp_path / "image.pb"), "--flood-stamp", "header.stamp",
        "--flood-wire-type", "gz.msgs.Image", "--flood-hz", "100", "--flood-lead", "0.3",
    )  # fmt: skip
    wait_for_line(peer, r"^FLOOD_START$", 15)
    wait_for_line(peer, r"^START$", 5)
    sent = int(wait_for_line(peer, r"^SENT (\d+)", 15)[1])
    flooded = int(wait_for_line(peer, r"^FLOOD_SENT (\d+)", 5)[1])
    clocks.wait_for_count(sent, timeout=5)
    arrived = images.wait_for_count(flooded, timeout=5)

    # The flood ran from its lead before the first clock message to after the last one.
    assert flooded >= 100 * (0.3 + 0.5) * 0.8
    assert len(arrived) == flooded
    last_clock = max(msg.sim.sec * NS + msg.sim.nsec for msg, _ in clocks.items())
    stamps = [msg.header.stamp.sec * NS + msg.header.stamp.nsec for msg, _ in arrived]
    assert stamps[-1] > last_clock
    for msg, info in arrived:
        assert info.msg_type == "gz.msgs.Image"
        msg.header.ClearField("stamp")
        assert msg == frame


def test_pub_fleet_publishes_every_spec_line_at_its_rate_and_counts_what_it_subscribes(
    ign_peer: Path, gz_node: Any, tmp_path: Path
) -> None:
    odometry, twist = message_class("gz.msgs.Odometry"), message_class("gz.msgs.Twist")
    fast, slow, command = (unique_name(stem) for stem in ("fleet_fast", "fleet_slow", "fleet_cmd"))
    spec = tmp_path / "fleet.spec"
    spec.write_text(
        "# a comment, then a blank line\n\n"
        f"pub ignition.msgs.Odometry 200 {fast} pose {{ position {{ x: 1.5 }} }}\n"
        f"pub ignition.msgs.Odometry 20 {slow} pose {{ position {{ x: -2.5 }} }}\n"
        f"sub ignition.msgs.Twist {command}\n"
    )
    inboxes = {fast: Inbox(), slow: Inbox()}
    for topic, inbox in inboxes.items():
        gz_node.subscribe_typed(topic, odometry, inbox, msg_type="ignition.msgs.Odometry")
    peer = start_peer("pub-fleet", str(spec), "0")
    wait_for_line(peer, r"^READY$", 15)
    publisher = gz_node.advertise(command, "ignition.msgs.Twist")
    wait_until(publisher.has_connections, 10, "the peer's subscription")
    deadline = time.monotonic() + 10
    sent = 0
    while "FIRST " not in peer.output() and time.monotonic() < deadline:
        publisher.publish(twist(linear={"x": 0.75}))
        sent += 1
        time.sleep(0.05)
    for inbox in inboxes.values():
        inbox.wait_for_count(2, timeout=10)
    peer.stop()

    first = wait_for_line(peer, rf"^FIRST {command} (.*)$", 5)[1]
    assert first == "linear { x: 0.75 }"
    counts = {name: int(n) for name, n in re.findall(r"^SENT (\S+) (\d+)$", peer.output(), re.M)}
    assert counts.keys() == {fast, slow}
    assert counts[fast] > counts[slow] > 0  # each line at its own rate
    received = int(wait_for_line(peer, rf"^RECEIVED {command} (\d+)$", 5)[1])
    assert 0 < received <= sent
    wait_for_line(peer, r"^DONE$", 5)
    for topic, x in ((fast, 1.5), (slow, -2.5)):
        assert {msg.pose.position.x for msg, _ in inboxes[topic].items()} == {x}


def test_pub_fleet_names_the_spec_line_it_cannot_read(ign_peer: Path, tmp_path: Path) -> None:
    spec = tmp_path / "fleet.spec"
    spec.write_text("pub ignition.msgs.Clock 10 /clock\npublish ignition.msgs.Twist /x\n")
    peer = start_peer("pub-fleet", str(spec), "1")
    assert peer.wait(10) == 2
    assert "spec line 2: starts with publish, not pub or sub" in peer.output()

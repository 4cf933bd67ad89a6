"""image_bridge end to end: real Gazebo publishers (the C++ ign peer, our ZmqGzNode), real rclpy.

One lazy ``image_bridge`` process serves most tests: two plain topics, a renamed one, a lazy
probe, a topic for bad frames, and a config file with one image entry and one entry it skips;
``camera_info:=true`` and an invalid ``qos`` value are set too. A second, short-lived process
bridges Fortress-named images (``gz_type:=ignition.msgs.Image``) and is stopped with SIGINT.
"""

from __future__ import annotations

import signal
import subprocess
import sys
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import pytest
from diagnostic_msgs.msg import DiagnosticArray
from sensor_msgs.msg import CameraInfo, Image

from ros_gz_bridge_py.transport import GzNode
from testing.behaviour_harness import (
    WAIT,
    RosSide,
    gz_node,
    holds_for,
    publish_until,
    ros_side,
    started,
)
from testing.gzpeer import (
    Inbox,
    PeerProcess,
    require_peer,
    start_peer,
    start_process,
    unique_name,
    wait_for_line,
    wait_until,
)
from tests.bridge.image_frames import (
    UNSUPPORTED_FORMAT,
    camera_info,
    image_bridge_command,
    pattern_bytes,
    rgb_frame,
    rgb_text_proto,
)

__all__ = ["gz_node", "ros_side", "started"]

pytestmark = [pytest.mark.ros, pytest.mark.peer]

HEARTBEAT_MS = 200
WIDTH, HEIGHT = 4, 2
GZ_IMAGE = "gz.msgs.Image"


@dataclass(frozen=True)
class Topics:
    """Image topics of the shared bridge (each in a folder of its own, for camera_info)."""

    peer: str
    ours: str
    renamed_gz: str
    renamed_ros: str
    lazy: str
    bad: str
    yaml_gz: str
    yaml_ros: str

    @classmethod
    def make(cls) -> Topics:
        return cls(
            peer=unique_name("img_peer") + "/image",
            ours=unique_name("img_ours") + "/image",
            renamed_gz=unique_name("img_gz_name") + "/image",
            renamed_ros=unique_name("img_ros_name").lstrip("/") + "/image",
            lazy=unique_name("img_lazy") + "/image",
            bad=unique_name("img_bad") + "/image",
            yaml_gz=unique_name("img_yaml_gz") + "/image",
            yaml_ros=unique_name("img_yaml_ros") + "/image",
        )


@dataclass
class SharedBridge:
    process: PeerProcess
    topics: Topics


@pytest.fixture(scope="module")
def bridge(tmp_path_factory: pytest.TempPathFactory) -> Iterator[SharedBridge]:
    require_peer()
    topics = Topics.make()
    config = tmp_path_factory.mktemp("image_bridge") / "cams.yaml"
    config.write_text(
        f"- ros_topic_name: {topics.yaml_ros}\n"
        f"  gz_topic_name: {topics.yaml_gz}\n"
        "  ros_type_name: sensor_msgs/msg/Image\n"
        f"  gz_type_name: {GZ_IMAGE}\n"
        "- topic_name: /not_an_image\n"
        "  ros_type_name: std_msgs/msg/String\n"
        "  gz_type_name: gz.msgs.StringMsg\n"
    )
    command = image_bridge_command(
        topics.peer,
        topics.ours,
        f"{topics.renamed_gz}:={topics.renamed_ros}",
        topics.lazy,
        topics.bad,
        ros_args=[
            "-p", "lazy:=true",
            "-p", f"subscription_heartbeat:={HEARTBEAT_MS}",
            "-p", "camera_info:=true",
            "-p", "qos:=bogus",
            "-p", f"config_file:={config}",
            "-p", "status_period:=0.5",
            "-p", "camera_infos:=true",
        ],
    )  # fmt: skip
    process = start_process(command)
    try:
        # Six images (five arguments, one config entry) and their six camera infos.
        for _ in range(12):
            wait_for_line(process, r"Creating GZ->ROS", timeout=30)
        yield SharedBridge(process, topics)
        process.send_signal(signal.SIGTERM)
        status = process.wait(WAIT)
    finally:
        process.stop()
    assert status == 0, process.output()


def _subscribe(ros: RosSide, msg_type: Any, topic: str) -> tuple[Inbox, Any]:
    """A reliable subscription, once the bridge's publisher is visible."""
    wait_until(lambda: ros.count_publishers(topic) >= 1, WAIT, f"a publisher on {topic}")
    return ros.subscribe(msg_type, topic)


def _assert_pattern_image(msg: Any, frame_id: str) -> None:
    assert (msg.width, msg.height) == (WIDTH, HEIGHT)
    assert msg.encoding == "rgb8"
    assert msg.step == WIDTH * 3
    assert msg.is_bigendian == 0
    assert bytes(msg.data) == pattern_bytes(WIDTH * HEIGHT * 3)
    assert msg.header.frame_id == frame_id


def test_node_is_ros_gz_image(bridge: SharedBridge, ros_side: RosSide) -> None:
    wait_until(
        lambda: "ros_gz_image" in ros_side.run(ros_side.node.get_node_names),
        WAIT,
        "the ros_gz_image node",
    )


def test_two_topics_from_real_publishers(
    bridge: SharedBridge, ros_side: RosSide, gz_node: GzNode, started: list[PeerProcess]
) -> None:
    topics = bridge.topics
    peer_inbox, _ = _subscribe(ros_side, Image, topics.peer)
    ours_inbox, _ = _subscribe(ros_side, Image, topics.ours)
    peer = start_peer(
        "pub", topics.peer, "ignition.msgs.Image", "20", "0",
        rgb_text_proto(WIDTH, HEIGHT, "cam::optical"),
        "--bytes", str(WIDTH * HEIGHT * 3), "--wire-type", GZ_IMAGE, "--wait", str(WAIT),
    )  # fmt: skip
    started.append(peer)
    publisher = gz_node.advertise(topics.ours, GZ_IMAGE)
    frame = rgb_frame(WIDTH, HEIGHT, frame_id="ours")
    publish_until(
        lambda _i: publisher.publish(frame),
        lambda: bool(ours_inbox.items()) and bool(peer_inbox.items()),
        "both topics arrive",
    )
    _assert_pattern_image(peer_inbox.items()[0][0], "cam/optical")
    _assert_pattern_image(ours_inbox.items()[0][0], "ours")


def test_renamed_topic(bridge: SharedBridge, ros_side: RosSide, gz_node: GzNode) -> None:
    topics = bridge.topics
    inbox, _ = _subscribe(ros_side, Image, "/" + topics.renamed_ros)
    publisher = gz_node.advertise(topics.renamed_gz, GZ_IMAGE)
    frame = rgb_frame(WIDTH, HEIGHT)
    publish_until(lambda _i: publisher.publish(frame), lambda: bool(inbox.items()), "rename")
    _assert_pattern_image(inbox.items()[0][0], "")
    assert ros_side.count_publishers(topics.renamed_gz) == 0


def test_config_file_image_entry(bridge: SharedBridge, ros_side: RosSide, gz_node: GzNode) -> None:
    topics = bridge.topics
    inbox, _ = _subscribe(ros_side, Image, topics.yaml_ros)
    publisher = gz_node.advertise(topics.yaml_gz, GZ_IMAGE)
    frame = rgb_frame(WIDTH, HEIGHT)
    publish_until(lambda _i: publisher.publish(frame), lambda: bool(inbox.items()), "yaml entry")
    _assert_pattern_image(inbox.items()[0][0], "")
    assert "skipped (std_msgs/msg/String)" in bridge.process.output()


def test_camera_info_beside_the_image(
    bridge: SharedBridge, ros_side: RosSide, gz_node: GzNode
) -> None:
    info_topic = bridge.topics.ours.rsplit("/", 1)[0] + "/camera_info"
    inbox, _ = _subscribe(ros_side, CameraInfo, info_topic)
    publisher = gz_node.advertise(info_topic, "gz.msgs.CameraInfo")
    info = camera_info(WIDTH, HEIGHT)
    publish_until(lambda _i: publisher.publish(info), lambda: bool(inbox.items()), "camera info")
    received = inbox.items()[0][0]
    assert (received.width, received.height) == (WIDTH, HEIGHT)
    assert list(received.k) == list(info.intrinsics.k)
    assert received.distortion_model == "plumb_bob"
    assert list(received.d) == list(info.distortion.k)


def test_lazy_subscribes_to_gazebo_only_while_ros_listens(
    bridge: SharedBridge, ros_side: RosSide, gz_node: GzNode
) -> None:
    topic = bridge.topics.lazy
    publisher = gz_node.advertise(topic, GZ_IMAGE)
    wait_until(lambda: ros_side.count_publishers(topic) >= 1, WAIT, "the bridge's publisher")
    assert holds_for(lambda: not publisher.has_connections(), 5 * HEARTBEAT_MS / 1000)
    inbox, subscription = ros_side.subscribe(Image, topic)
    wait_until(publisher.has_connections, WAIT, "the bridge subscribing in Gazebo")
    frame = rgb_frame(WIDTH, HEIGHT)
    publish_until(lambda _i: publisher.publish(frame), lambda: bool(inbox.items()), "lazy image")
    ros_side.destroy(subscription)
    wait_until(lambda: not publisher.has_connections(), WAIT, "the bridge unsubscribing")


def test_bad_frames_are_reported_and_skipped(
    bridge: SharedBridge, ros_side: RosSide, gz_node: GzNode
) -> None:
    topic = bridge.topics.bad
    inbox, _ = _subscribe(ros_side, Image, topic)
    publisher = gz_node.advertise(topic, GZ_IMAGE)
    wait_until(publisher.has_connections, WAIT, "the bridge subscribing in Gazebo")
    short = rgb_frame(WIDTH, HEIGHT, data=pattern_bytes(WIDTH * HEIGHT * 3 - 1))
    publish_until(
        lambda _i: publisher.publish(short),
        lambda: f"{topic} ({GZ_IMAGE})" in _skipped_lines(bridge.process),
        "the short frame to be reported",
    )
    unsupported = rgb_frame(WIDTH, HEIGHT)
    unsupported.pixel_format_type = UNSUPPORTED_FORMAT
    good = rgb_frame(WIDTH, HEIGHT)
    publish_until(
        lambda i: publisher.publish(good if i % 3 == 2 else unsupported),
        lambda: bool(inbox.items()),
        "a good frame after bad ones",
    )
    for msg, _ in inbox.items():
        _assert_pattern_image(msg, "")


def test_status_period_publishes_each_topic_on_diagnostics(
    bridge: SharedBridge, ros_side: RosSide
) -> None:
    """image_bridge took status_period without a word and published nothing."""
    arrays = Inbox()
    subscription = ros_side.run(
        lambda: ros_side.node.create_subscription(
            DiagnosticArray, "/diagnostics", lambda m: arrays(m, None), 10
        )
    )
    renamed = f"/{bridge.topics.renamed_ros}"

    def names() -> set[str]:
        return {
            status.name
            for array, _ in arrays.items()
            for status in array.status
            if status.hardware_id == "/ros_gz_image"
        }

    try:
        wait_until(lambda: any(n.endswith(f" {renamed}") for n in names()), WAIT, "its status")
    finally:
        ros_side.destroy(subscription)
    assert any(name.endswith(f" {bridge.topics.peer}") for name in names())


def _skipped_lines(process: PeerProcess) -> str:
    return "\n".join(line for line in process.output().splitlines() if "message skipped" in line)


def test_a_misspelt_parameter_is_named_with_the_one_meant(bridge: SharedBridge) -> None:
    assert (
        "parameter camera_infos is none of image_bridge's, so it changes nothing; did you "
        "mean camera_info"
    ) in bridge.process.output()


def test_invalid_qos_is_logged_and_default_used(bridge: SharedBridge) -> None:
    assert "Invalid QoS profile bogus specified. Using default profile." in bridge.process.output()


def test_fortress_type_name_frame_override_and_sigint(
    ros_side: RosSide, started: list[PeerProcess]
) -> None:
    require_peer()
    topic = unique_name("img_fortress")
    process = start_process(
        image_bridge_command(
            topic,
            ros_args=["-p", "gz_type:=ignition.msgs.Image", "-p", "override_frame_id:=optical"],
        )
    )
    started.append(process)
    wait_for_line(process, r"Creating GZ->ROS .*ignition\.msgs\.Image", timeout=30)
    inbox, _ = _subscribe(ros_side, Image, topic)
    peer = start_peer(
        "pub", topic, "ignition.msgs.Image", "20", "0",
        rgb_text_proto(WIDTH, HEIGHT, "fortress"),
        "--bytes", str(WIDTH * HEIGHT * 3), "--wait", str(WAIT),
    )  # fmt: skip
    started.append(peer)
    inbox.wait_for_count(1, WAIT)
    _assert_pattern_image(inbox.items()[0][0], "optical")
    process.send_signal(signal.SIGINT)
    assert process.wait(WAIT) == 0, process.output()


def test_no_type_parameter_takes_publishers_of_every_gazebo_line(
    ros_side: RosSide, started: list[PeerProcess]
) -> None:
    """No ``gz_type``: a Fortress camera (``ignition.msgs.Image``) and a Harmonic one
    (``gz.msgs.Image`` on the wire) both arrive, each frame intact."""
    require_peer()
    fortress, harmonic = unique_name("img_fortress_cam"), unique_name("img_harmonic_cam")
    process = start_process(image_bridge_command(fortress, harmonic))
    started.append(process)
    wait_for_line(process, rf"Creating GZ->ROS .*{harmonic}", timeout=30)
    inboxes = {topic: _subscribe(ros_side, Image, topic)[0] for topic in (fortress, harmonic)}
    for topic, wire_type in ((fortress, "ignition.msgs.Image"), (harmonic, GZ_IMAGE)):
        peer = start_peer(
            "pub", topic, "ignition.msgs.Image", "20", "0",
            rgb_text_proto(WIDTH, HEIGHT, "cam"),
            "--bytes", str(WIDTH * HEIGHT * 3), "--wait", str(WAIT), "--wire-type", wire_type,
        )  # fmt: skip
        started.append(peer)
    for inbox in inboxes.values():
        inbox.wait_for_count(1, WAIT)
        _assert_pattern_image(inbox.items()[0][0], "cam")


def _run(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        image_bridge_command(*args), capture_output=True, text=True, timeout=60, check=False
    )


def test_no_arguments_prints_usage_on_stderr_and_exits_255() -> None:
    done = _run()
    assert done.returncode == 255
    assert done.stdout == ""
    assert "usage: image_bridge TOPIC" in done.stderr


def test_help_prints_usage_on_stdout() -> None:
    done = _run("-h")
    assert done.returncode == 0
    assert "usage: image_bridge TOPIC" in done.stdout


def test_bad_argument_is_named() -> None:
    done = _run("/ok", "/gz:=")
    assert done.returncode == 255
    assert "argument 2 '/gz:='" in done.stderr


def test_only_ros_arguments_is_nothing_to_bridge() -> None:
    done = _run("--ros-args", "-p", "qos:=sensor_data")
    assert done.returncode == 255
    assert "No image topics to bridge" in done.stderr


def test_only_refused_topics_is_nothing_to_bridge() -> None:
    """It kept running with no bridge, after one error (found by a new user)."""
    done = _run("/camera/image/")
    assert done.returncode == 255
    assert "No image topic could be bridged (each is refused above)" in done.stderr
    # The fix is this command line's, not a YAML entry's.
    assert "though Gazebo takes it: give it one: image_bridge /camera/image/:=<ROS name>" in (
        done.stderr
    )


def test_console_script_runs_the_same_main() -> None:
    script = Path(sys.prefix) / "bin" / "image_bridge"
    done = subprocess.run([str(script)], capture_output=True, text=True, timeout=60, check=False)
    assert done.returncode == 255
    assert "usage: image_bridge TOPIC" in done.stderr

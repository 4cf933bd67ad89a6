"""Namespaces everywhere (issue 16, point 4): with ``-r __ns:=/robotN`` and
``expand_gz_topic_names``, a command-line bridge and ``image_bridge`` take their relative
Gazebo names in the namespace, as YAML entries do, and publish under it in ROS. The Gazebo
side is the real C++ Fortress peer.
"""

from __future__ import annotations

import pytest
from sensor_msgs.msg import Image
from std_msgs.msg import String

from testing.behaviour_harness import WAIT, RosSide, bridge_command, probe, relative, started
from testing.gzpeer import (
    PeerProcess,
    require_peer,
    start_peer,
    start_process,
    unique_name,
    wait_for_line,
    wait_until,
)
from tests.bridge.image_frames import image_bridge_command, rgb_text_proto

__all__ = ["probe", "started"]

pytestmark = [pytest.mark.ros, pytest.mark.peer]


def test_a_namespaced_command_line_bridge_and_image_bridge_publish_under_it(
    probe: RosSide, started: list[PeerProcess]
) -> None:
    require_peer()
    chatter, camera = relative(unique_name("ns_chatter")), relative(unique_name("ns_cam"))
    started.append(
        start_peer(
            "pub", f"/robot1/{chatter}", "ignition.msgs.StringMsg", "10", "0", 'data: "r1"',
            "--wait", "0",
        )
    )  # fmt: skip
    started.append(
        start_peer(
            "pub", f"/robot2/{camera}/image", "ignition.msgs.Image", "10", "0",
            rgb_text_proto(2, 2, "cam"), "--bytes", "12", "--wait", "0",
        )
    )  # fmt: skip
    namespaced = ["-p", "expand_gz_topic_names:=true"]
    cli = start_process(
        bridge_command(
            f"{chatter}@std_msgs/msg/String[gz.msgs.StringMsg",
            ros_args=["-r", "__ns:=/robot1", *namespaced],
        )
    )
    images = start_process(
        image_bridge_command(f"{camera}/image", ros_args=["-r", "__ns:=/robot2", *namespaced])
    )
    started += [cli, images]
    # The C++ creation line names the ROS topic as given; our next line says what it resolved to.
    wait_for_line(
        cli, rf"Creating GZ->ROS Bridge: \[/robot1/{chatter} .* -> {chatter} ", timeout=30
    )
    wait_for_line(cli, rf"the ROS name {chatter} resolves to /robot1/{chatter}$", timeout=30)
    wait_for_line(images, rf"Creating GZ->ROS Bridge: \[/robot2/{camera}/image ", timeout=30)
    for topic in (f"/robot1/{chatter}", f"/robot2/{camera}/image"):
        wait_until(
            lambda: probe.count_publishers(topic) == 1,  # noqa: B023 - called in this iteration
            WAIT,
            f"a publisher of {topic}",
        )
    strings, _ = probe.subscribe(String, f"/robot1/{chatter}")
    frames, _ = probe.subscribe(Image, f"/robot2/{camera}/image")
    assert strings.wait_for_count(1, WAIT)[0][0].data == "r1"
    frame = frames.wait_for_count(1, WAIT)[0][0]
    assert (frame.width, frame.height, frame.header.frame_id) == (2, 2, "cam")
    assert probe.count_publishers(f"/{chatter}") == 0
    assert probe.count_publishers(f"/{camera}/image") == 0

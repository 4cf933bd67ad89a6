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


def test_a_remap_rule_for_the_bridge_node_reaches_every_endpoint(
    probe: RosSide, started: list[PeerProcess]
) -> None:
    """``-r ros_gz_bridge:/a:=/b`` moved the bridge node's publishers, but the subscriptions
    and services on its helper nodes stayed on /a while the log said /a resolves to /b."""
    both, one_way = unique_name("remap_both"), unique_name("remap_one_way")
    service = unique_name("remap_control")
    renamed = {name: f"{name}_renamed" for name in (both, one_way, service)}
    rules = [arg for old, new in renamed.items() for arg in ("-r", f"ros_gz_bridge:{old}:={new}")]
    bridge = start_process(
        bridge_command(
            f"{both}@std_msgs/msg/String@gz.msgs.StringMsg",  # its subscription: the side node
            f"{one_way}@std_msgs/msg/String]gz.msgs.StringMsg",  # the native loop's node
            f"{service}@ros_gz_interfaces/srv/ControlWorld",
            ros_args=[*rules, "-r", "other_node:/x:=/y"],
        )
    )
    started.append(bridge)
    wait_for_line(bridge, rf"the ROS name {service} resolves to {renamed[service]}", timeout=30)
    for topic in (both, one_way):
        new = renamed[topic]
        wait_until(
            lambda: probe.count_subscribers(new) == 1,  # noqa: B023 - called in this iteration
            WAIT,
            f"the bridge's subscription of {new}",
        )
        assert probe.count_subscribers(topic) == 0
    assert probe.count_publishers(renamed[both]) == 1

    def services() -> set[str]:
        return {name for name, _ in probe.run(probe.node.get_service_names_and_types)}

    wait_until(lambda: renamed[service] in services(), WAIT, f"the service {renamed[service]}")
    assert service not in services()

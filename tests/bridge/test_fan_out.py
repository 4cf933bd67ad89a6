"""One Gazebo topic bridged to several ROS topics or types, end to end.

The C++ bridge lets several entries read one Gazebo topic: a model's ``Pose_V`` to ``/tf`` and
to a ``PoseArray``, one topic under two ROS names. Each entry is a channel of its own, and each
must carry every message, whichever path it takes: on the native data plane the first channel of
a topic reads the node's shared SUB socket and a second one a socket of its own
(``transport/zmq/shared_sub.py`` ``claim``); under ``ROS_GZ_BRIDGE_NATIVE=off`` (the suite also
runs so) both are Python subscriptions of one route. The Gazebo side is the C++ Fortress peer,
the ROS side an rclpy node of this process, the bridge a real ``parameter_bridge`` process.
"""

from __future__ import annotations

from pathlib import Path

import pytest
from geometry_msgs.msg import PoseArray
from std_msgs.msg import String
from tf2_msgs.msg import TFMessage

from testing.behaviour_harness import STRING, WAIT, RosSide, ros_side, start_bridge, started
from testing.gzpeer import PeerProcess, require_peer, start_peer, unique_name

__all__ = ["ros_side", "started"]

pytestmark = [pytest.mark.ros, pytest.mark.peer]

POSE_V = "ignition.msgs.Pose_V"
POSES = " ".join(
    f'pose {{ header {{ data {{ key: "frame_id" value: "world" }} '
    f'data {{ key: "child_frame_id" value: "{child}" }} }} position {{ {position} }} }}'
    for child, position in (("arm", "x: 1.5 y: -2"), ("base", "z: 3"))
)


def _entry(gz_topic: str, ros_topic: str, ros_type: str, gz_type: str) -> str:
    return (
        f"- gz_topic_name: {gz_topic}\n"
        f"  ros_topic_name: {ros_topic}\n"
        f"  ros_type_name: {ros_type}\n"
        f"  gz_type_name: {gz_type}\n"
        "  direction: GZ_TO_ROS\n"
    )


def test_every_entry_of_one_gazebo_topic_carries_its_messages(
    tmp_path: Path, ros_side: RosSide, started: list[PeerProcess]
) -> None:
    require_peer()
    text, poses = unique_name("fan_text"), unique_name("fan_poses")
    config = tmp_path / "fan_out.yaml"
    config.write_text(
        _entry(text, f"{text}_a", "std_msgs/msg/String", STRING)
        + _entry(text, f"{text}_b", "std_msgs/msg/String", STRING)
        + _entry(poses, f"{poses}_tf", "tf2_msgs/msg/TFMessage", POSE_V)
        + _entry(poses, f"{poses}_array", "geometry_msgs/msg/PoseArray", POSE_V)
    )
    bridge = start_bridge(ros_args=["-p", f"config_file:={config}"], creating=4)
    started.append(bridge)
    inboxes = {
        "a": ros_side.subscribe(String, f"{text}_a")[0],
        "b": ros_side.subscribe(String, f"{text}_b")[0],
        "tf": ros_side.subscribe(TFMessage, f"{poses}_tf")[0],
        "array": ros_side.subscribe(PoseArray, f"{poses}_array")[0],
    }
    started.append(start_peer("pub-many", STRING, "20", 'data: "fan"', text))
    started.append(start_peer("pub-many", POSE_V, "20", POSES, poses))

    for name in ("a", "b"):
        message = inboxes[name].wait_for_count(3, WAIT * 2)[-1][0]
        assert message.data == "fan", name
    transforms = inboxes["tf"].wait_for_count(3, WAIT * 2)[-1][0].transforms
    assert [t.child_frame_id for t in transforms] == ["arm", "base"]
    assert (transforms[0].transform.translation.x, transforms[0].transform.translation.y) == (
        1.5,
        -2.0,
    )
    array = inboxes["array"].wait_for_count(3, WAIT * 2)[-1][0].poses
    assert [(p.position.x, p.position.y, p.position.z) for p in array] == [
        (1.5, -2.0, 0.0),
        (0.0, 0.0, 3.0),
    ]
    output = bridge.output()
    assert "Failed to create" not in output
    assert "Traceback" not in output

"""YAML configuration errors as the running bridge reports them.

An invalid entry is skipped with its index, its line and the C++ error text, and the valid
entries of the same file bridge; a value C++ cannot convert (``lazy: maybe``) is one more
invalid entry here, where it kills the C++ process, and so is an entry that bridges what an
earlier one bridges (C++ builds it: every message twice). A missing file is one error, once.
"""

from __future__ import annotations

import time
from pathlib import Path

import pytest

from ros_gz_bridge_py.transport import GzNode
from testing.behaviour_harness import (
    STRING,
    WAIT,
    RosSide,
    gz_node,
    ros_side,
    start_bridge,
    started,
)
from testing.gzpeer import PeerProcess, require_peer, unique_name, wait_for_line, wait_until

__all__ = ["gz_node", "ros_side", "started"]

pytestmark = [pytest.mark.ros, pytest.mark.peer]

HEARTBEAT_MS = 200


def test_invalid_entries_are_reported_and_valid_ones_bridge(
    tmp_path: Path, gz_node: GzNode, ros_side: RosSide, started: list[PeerProcess]
) -> None:
    require_peer()
    first, last = unique_name("yaml_first"), unique_name("yaml_last")
    config = tmp_path / "mixed.yaml"
    config.write_text(
        f"- topic_name: {first}\n"  # entry 1, line 1
        "  ros_type_name: std_msgs/msg/String\n"
        f"  gz_type_name: {STRING}\n"
        "  direction: GZ_TO_ROS\n"
        "\n"
        "- topic_name: /both\n"  # entry 2, line 6
        "  ros_topic_name: /both_ros\n"
        "  ros_type_name: std_msgs/msg/String\n"
        f"  gz_type_name: {STRING}\n"
        "- topic_name: /maybe\n"  # entry 3, line 10
        "  ros_type_name: std_msgs/msg/String\n"
        f"  gz_type_name: {STRING}\n"
        "  lazy: maybe\n"  # line 13
        f"- topic_name: {last}\n"  # entry 4, line 14
        "  ros_type_name: std_msgs/msg/String\n"
        f"  gz_type_name: {STRING}\n"
        "  direction: GZ_TO_ROS\n"
        f"- topic_name: {first}\n"  # entry 5, line 18: entry 1 again, in both directions
        "  ros_type_name: std_msgs/msg/String\n"
        "  gz_type_name: ignition.msgs.StringMsg\n"
    )
    bridge = start_bridge(ros_args=["-p", f"config_file:={config}"])
    started.append(bridge)

    exclusive = wait_for_line(bridge, r"\[ERROR\].*entry 2", timeout=30).string
    assert f"{config} entry 2 (line 6): " in exclusive
    assert exclusive.endswith(
        "Could not parse entry: topic_name and ros_topic_name are mutually exclusive"
    )
    unconvertible = wait_for_line(bridge, r"\[ERROR\].*entry 3", timeout=WAIT).string
    assert f"{config} entry 3 (line 13): Could not parse entry: lazy " in unconvertible
    assert "'maybe'" in unconvertible
    # C++ builds entry 5 too: a second ROS publisher, every message of entry 1 twice.
    twice = wait_for_line(bridge, r"\[ERROR\].*entry 5", timeout=WAIT).string
    assert f"{config} entry 5 (line 18): ROS {first} (std_msgs/msg/String) and Gazebo " in twice
    assert f"is bridged already by {config} entry 1 (line 1); a second bridge" in twice

    for topic in (first, last):
        publisher = gz_node.advertise(topic, STRING)
        try:
            wait_until(publisher.has_connections, WAIT, f"the bridge of {topic}")
        finally:
            publisher.close()
    # one participant announces its publishers together: the second would show with the first
    wait_until(lambda: ros_side.count_publishers(first) > 0, WAIT, "the ROS publisher")
    assert ros_side.count_publishers(first) == 1
    assert ros_side.count_subscribers(first) == 0  # nothing of entry 5 stayed
    assert "Traceback" not in bridge.output()


def test_missing_file_is_one_clear_error(tmp_path: Path, started: list[PeerProcess]) -> None:
    missing = tmp_path / "no_such_bridge.yaml"
    bridge = start_bridge(
        ros_args=["-p", f"config_file:={missing}", "-p", f"subscription_heartbeat:={HEARTBEAT_MS}"]
    )
    started.append(bridge)
    wait_for_line(bridge, r"No bridges are running", timeout=30)
    time.sleep(5 * HEARTBEAT_MS / 1000)  # C++ would log the error again on every heartbeat

    output = bridge.output()
    errors = [line for line in output.splitlines() if "[ERROR]" in line]
    assert errors == [line for line in errors if line.endswith(f"failed to open file [{missing}]")]
    assert len(errors) == 1, output
    assert "Could not parse config" in errors[0]
    assert "Traceback" not in output

"""A channel's /diagnostics level from what the status knows of it (no processes)."""

from __future__ import annotations

import dataclasses

from ros_gz_bridge_py.core.channel import ChannelState
from ros_gz_bridge_py.core.status import OK, STALE, WARN, ChannelStatus

IDLE = ChannelStatus(
    direction="GZ->ROS",
    ros_name="/lazy",
    gz_name="/lazy",
    ros_type="std_msgs/msg/String",
    gz_type="gz.msgs.StringMsg",
    state=ChannelState.LAZY_IDLE.value,
    received=0,
    published=0,
    errors=0,
    dropped=0,
    rate=0.0,
    new_problems=0,
    flow="waiting for ROS",
)
NO_PEER = "no Gazebo Transport process is heard at all; the bridge listens with ..."


def test_a_lazy_channel_nobody_reads_is_stale_while_nothing_is_wrong() -> None:
    assert IDLE.level == STALE
    assert IDLE.message() == "lazy: no subscribers, input side closed"
    active = dataclasses.replace(IDLE, state=ChannelState.ACTIVE.value, flow="flowing")
    assert active.level == OK


def test_a_misconfiguration_makes_a_lazy_channel_warn_with_its_cause() -> None:
    faulty = dataclasses.replace(IDLE, flow="waiting for Gazebo", why=NO_PEER, fault=True)
    assert faulty.level == WARN
    assert faulty.message() == f"waiting for Gazebo: {NO_PEER}"


def test_a_side_not_there_yet_is_explained_without_raising_the_level() -> None:
    waiting = dataclasses.replace(IDLE, flow="waiting for Gazebo", why="no Gazebo publisher")
    assert waiting.level == STALE
    assert waiting.message() == "waiting for Gazebo: no Gazebo publisher"

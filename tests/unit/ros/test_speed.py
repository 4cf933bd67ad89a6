"""When the executables apply the Fast DDS shared-memory profile (ros_speed.py), and the zombie
segments they remove first."""

from __future__ import annotations

import fcntl
import os
import time
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest

from ros_gz_bridge_py.app.settings import read_switches
from ros_gz_bridge_py.ros.speed import (
    PROFILE,
    Removed,
    apply_fastdds_profile,
    decide,
    remove_zombie_segments,
)

NS = {"f": "http://www.eprosima.com/XMLSchemas/fastRTPS_Profiles"}


@pytest.mark.parametrize("rmw", [None, "rmw_fastrtps_cpp", " rmw_fastrtps_cpp "])
def test_applied_for_fast_dds_without_user_profile(rmw: str | None) -> None:
    env = {"ROS_DOMAIN_ID": "3"} if rmw is None else {"RMW_IMPLEMENTATION": rmw}
    assert apply_fastdds_profile(env, enabled=True) == str(PROFILE)
    assert env["FASTRTPS_DEFAULT_PROFILES_FILE"] == str(PROFILE)


@pytest.mark.parametrize(
    ("env", "why"),
    [
        ({"RMW_IMPLEMENTATION": "rmw_cyclonedds_cpp"}, "not Fast DDS"),
        ({"RMW_IMPLEMENTATION": "rmw_zenoh_cpp"}, "not Fast DDS"),
        ({"FASTRTPS_DEFAULT_PROFILES_FILE": "/mine.xml"}, "FASTRTPS_DEFAULT_PROFILES_FILE"),
        ({"FASTDDS_DEFAULT_PROFILES_FILE": "/mine.xml"}, "FASTDDS_DEFAULT_PROFILES_FILE"),
        ({"ROS_GZ_BRIDGE_FASTDDS_PROFILE": "off"}, "ROS_GZ_BRIDGE_FASTDDS_PROFILE"),
        ({"ROS_GZ_BRIDGE_FASTDDS_PROFILE": "0"}, "ROS_GZ_BRIDGE_FASTDDS_PROFILE"),
        ({"ROS_GZ_BRIDGE_FASTDDS_PROFILE": "False"}, "ROS_GZ_BRIDGE_FASTDDS_PROFILE"),
    ],
)
def test_user_choices_win(env: dict[str, str], why: str) -> None:
    """The switch is read from the same environment, as the executables do."""
    before = dict(env)
    enabled = read_switches(env).fastdds_profile
    decision = decide(env, enabled=enabled)
    assert not decision.apply
    assert why in decision.reason
    assert apply_fastdds_profile(env, enabled=enabled) is None
    assert env == before


def test_empty_profile_variable_counts_as_unset() -> None:
    env = {"FASTDDS_DEFAULT_PROFILES_FILE": "", "ROS_GZ_BRIDGE_FASTDDS_PROFILE": "on"}
    assert apply_fastdds_profile(env, enabled=read_switches(env).fastdds_profile) == str(PROFILE)


def test_profile_is_a_default_participant_with_a_large_shm_segment() -> None:
    root = ET.parse(PROFILE).getroot()  # noqa: S314 - our own packaged file
    participant = root.find("f:participant", NS)
    assert participant is not None
    assert participant.get("is_default_profile") == "true"
    used = {t.text for t in participant.iterfind("f:rtps/f:userTransports/f:transport_id", NS)}
    kinds = {
        d.findtext("f:transport_id", namespaces=NS): d
        for d in root.iterfind("f:transport_descriptors/f:transport_descriptor", NS)
    }
    assert used == set(kinds)
    types = {d.findtext("f:type", namespaces=NS) for d in kinds.values()}
    assert types == {"SHM", "UDPv4"}
    shm = next(d for d in kinds.values() if d.findtext("f:type", namespaces=NS) == "SHM")
    assert int(shm.findtext("f:segment_size", "0", NS)) >= 64 * 1024 * 1024


def test_profile_makes_every_writer_suppress_nacks_for_20_ms() -> None:
    """The default data-writer profile (its effect on Fast DDS's event thread is measured in
    real processes by tests/ros/test_fastdds_profile.py)."""
    root = ET.parse(PROFILE).getroot()  # noqa: S314 - our own packaged file
    writer = root.find("f:data_writer", NS)
    assert writer is not None
    assert writer.get("is_default_profile") == "true"
    suppression = writer.find("f:times/f:nackSupressionDuration", NS)
    assert suppression is not None
    seconds = int(suppression.findtext("f:sec", "0", NS))
    nanoseconds = int(suppression.findtext("f:nanosec", "0", NS))
    assert (seconds, nanoseconds) == (0, 20_000_000)


# --- zombie Fast DDS segments --------------------------------------------------------------


def _segment(shm: Path, name: str, size: int, age: float) -> Path:
    """A segment and its lock file, as Fast DDS lays them out, the lock ``age`` seconds old."""
    (shm / name).write_bytes(bytes(size))
    lock = shm / f"{name}_el"
    lock.write_bytes(b"")
    then = time.time() - age
    os.utime(lock, (then, then))
    return lock


def test_segments_whose_owner_is_gone_are_removed_and_live_ones_kept(tmp_path: Path) -> None:
    _segment(tmp_path, "fastrtps_0123456789abcdef", 3000, age=60)
    _segment(tmp_path, "fastrtps_00000000000000aa", 2000, age=60)
    held = _segment(tmp_path, "fastrtps_fedcba9876543210", 1000, age=60)
    _segment(tmp_path, "fastrtps_1111111111111111", 500, age=1)  # being made, maybe
    _segment(tmp_path, "fastrtps_port7411", 100, age=60)  # ports are left alone
    (tmp_path / "other_el").write_bytes(b"")
    with held.open("ab") as owner:
        fcntl.flock(owner, fcntl.LOCK_EX | fcntl.LOCK_NB)  # a live process holds its lock
        removed = remove_zombie_segments(tmp_path, min_age=10)
    assert (removed.segments, removed.size) == (2, 5000)
    assert sorted(p.name for p in tmp_path.iterdir()) == [
        "fastrtps_1111111111111111",
        "fastrtps_1111111111111111_el",
        "fastrtps_fedcba9876543210",
        "fastrtps_fedcba9876543210_el",
        "fastrtps_port7411",
        "fastrtps_port7411_el",
        "other_el",
    ]
    assert removed.describe() == (
        "removed 2 Fast DDS shared-memory segments (0 MB) left by processes that exited "
        "without closing them"
    )


def test_no_shared_memory_directory_removes_nothing(tmp_path: Path) -> None:
    assert remove_zombie_segments(tmp_path / "missing") == Removed(0, 0)

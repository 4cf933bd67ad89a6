"""When the executables apply the Fast DDS shared-memory profile (ros_speed.py)."""

from __future__ import annotations

import xml.etree.ElementTree as ET

import pytest

from ros_gz_bridge_py.app.settings import read_switches
from ros_gz_bridge_py.ros.speed import PROFILE, apply_fastdds_profile, decide

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

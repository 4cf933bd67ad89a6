"""The command-line bridge forms users write (``shared/data/configs/README.md``), end to end.

One ``parameter_bridge`` gets every form at once, each on its own topic: ``[`` (Gazebo->ROS),
``]`` (ROS->Gazebo) and ``@`` (both ways), with ``ignition.msgs.*`` names (the C++ peer's
native Fortress types, including the Fortress ``IMU`` layout) and ``gz.msgs.*`` names (the peer
sends Harmonic type names with ``--wire-type``). Each form carries a message in each of its
directions, checked field by field; the bracket forms carry nothing the other way.
"""

from __future__ import annotations

import functools
import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import pytest

from testing.e2e_harness import (
    RUN_TIMEOUT,
    GzEcho,
    ProcessGroup,
    RosChecker,
    parse_gz,
    wait_all,
)
from testing.gzpeer import PeerProcess, unique_name
from tests.bridge.e2e_values import (
    CLOCK,
    IMU_FORTRESS,
    JOINT_STATES,
    SCAN,
    SCAN_TO_GZ,
    TWIST_FROM_GZ,
    TWIST_FROM_GZ_NOT_BRIDGED,
    TWIST_TO_GZ,
    GzSample,
    RosSample,
    mismatches,
)

pytestmark = [pytest.mark.peer, pytest.mark.ros]

#: How long the against-the-direction publishers keep going after everything arrived.
REVERSE_DWELL = 2.0


@dataclass(frozen=True)
class Form:
    """One ``TOPIC@ROS_TYPE<marker>GZ_TYPE`` argument and what it must carry."""

    label: str
    ros_type: str
    marker: str
    gz_type: str
    to_ros: GzSample | None
    to_gz: RosSample | None
    topic: str

    @property
    def argument(self) -> str:
        return f"{self.topic}@{self.ros_type}{self.marker}{self.gz_type}"


def _form(
    label: str,
    ros_type: str,
    marker: str,
    gz_type: str,
    *,
    to_ros: GzSample | None = None,
    to_gz: RosSample | None = None,
) -> Form:
    return Form(label, ros_type, marker, gz_type, to_ros, to_gz, unique_name(f"inline_{label}"))


TWIST = "geometry_msgs/msg/Twist"
JOINTS = "sensor_msgs/msg/JointState"
SCAN_TYPE = "sensor_msgs/msg/LaserScan"
FORMS = (
    # The README's forms, each on a topic of its own.
    _form("twist_from_ign", TWIST, "[", "ignition.msgs.Twist", to_ros=TWIST_FROM_GZ),
    _form("joints_from_ign", JOINTS, "[", "ignition.msgs.Model", to_ros=JOINT_STATES),
    _form("imu_from_ign", "sensor_msgs/msg/Imu", "[", "ignition.msgs.IMU", to_ros=IMU_FORTRESS),
    _form("twist_both_gz", TWIST, "@", "gz.msgs.Twist", to_ros=TWIST_FROM_GZ, to_gz=TWIST_TO_GZ),
    _form("scan_both_gz", SCAN_TYPE, "@", "gz.msgs.LaserScan", to_ros=SCAN, to_gz=SCAN_TO_GZ),
    _form("clock_from_gz", "rosgraph_msgs/msg/Clock", "[", "gz.msgs.Clock", to_ros=CLOCK),
    # And the ROS->Gazebo bracket.
    _form("twist_to_ign", TWIST, "]", "ignition.msgs.Twist", to_gz=TWIST_TO_GZ),
)
#: The bracket forms that get traffic against their direction (both Twist).
AGAINST_TO_GZ = FORMS[0]
AGAINST_TO_ROS = FORMS[-1]


@dataclass
class InlineRun:
    bridge: PeerProcess
    checker: RosChecker
    echoes: dict[str, GzEcho]


def _arrived_in_ros(checker: RosChecker, form: Form) -> bool:
    assert form.to_ros is not None
    expected = form.to_ros.ros
    return any(not mismatches(expected, msg) for msg in checker.messages(form.topic))


def _arrived_in_gazebo(echo: GzEcho, expected: Any) -> bool:
    return expected in echo.messages()


def _expected_gz(sample: RosSample) -> Any:
    return parse_gz(sample.gz_type_name, sample.gz_text)


@pytest.fixture(scope="module")
def run(module_processes: ProcessGroup) -> InlineRun:
    group = module_processes
    bridge = group.bridge(*(form.argument for form in FORMS))
    echoes: dict[str, GzEcho] = {}
    publish: list[tuple[str, str, dict[str, Any]]] = []
    for form in FORMS:
        if form.to_ros is not None:
            group.peer(*form.to_ros.peer_pub_args(form.topic, form.gz_type))
        if form.to_gz is not None:
            publish.append((form.topic, form.ros_type, form.to_gz.values))
            echoes[form.topic] = GzEcho.peer(
                group, form.topic, form.to_gz.gz_type_name, form.gz_type
            )
    # Against the direction of the brackets.
    publish.append((AGAINST_TO_GZ.topic, TWIST, TWIST_TO_GZ.values))
    echoes[AGAINST_TO_GZ.topic] = GzEcho.peer(
        group, AGAINST_TO_GZ.topic, "Twist", "ignition.msgs.Twist"
    )
    group.peer(*TWIST_FROM_GZ_NOT_BRIDGED.peer_pub_args(AGAINST_TO_ROS.topic))
    checker = RosChecker(group, [(form.topic, form.ros_type) for form in FORMS], publish)

    checks: dict[str, Callable[[], bool]] = {}
    for form in FORMS:
        if form.to_ros is not None:
            checks[f"{form.label} to ROS"] = functools.partial(_arrived_in_ros, checker, form)
        if form.to_gz is not None:
            expected = _expected_gz(form.to_gz)
            checks[f"{form.label} to Gazebo"] = functools.partial(
                _arrived_in_gazebo, echoes[form.topic], expected
            )
    wait_all(checks, RUN_TIMEOUT)
    time.sleep(REVERSE_DWELL)
    return InlineRun(bridge, checker, echoes)


@pytest.mark.parametrize(
    "form", [form for form in FORMS if form.to_ros], ids=lambda form: form.label
)
def test_form_carries_gazebo_to_ros(run: InlineRun, form: Form) -> None:
    assert form.to_ros is not None
    arrived = run.checker.messages(form.topic)
    assert arrived, f"nothing arrived for {form.argument}; bridge:\n{run.bridge.output()}"
    problems = [mismatches(form.to_ros.ros, msg) for msg in arrived]
    assert any(not found for found in problems), f"{form.argument}: {problems}"


@pytest.mark.parametrize(
    "form", [form for form in FORMS if form.to_gz], ids=lambda form: form.label
)
def test_form_carries_ros_to_gazebo(run: InlineRun, form: Form) -> None:
    assert form.to_gz is not None
    expected = _expected_gz(form.to_gz)
    arrived = run.echoes[form.topic].messages()
    assert expected in arrived, (
        f"{form.argument}: expected {expected}, got {arrived[:3]}; bridge:\n{run.bridge.output()}"
    )


def test_brackets_carry_nothing_against_their_direction(run: InlineRun) -> None:
    assert run.checker.matched(AGAINST_TO_GZ.topic) is False, (
        f"{AGAINST_TO_GZ.argument} subscribed in ROS"
    )
    gz_side = run.echoes[AGAINST_TO_GZ.topic].messages()
    assert gz_side, "the Gazebo echo heard nothing, not even the Gazebo publisher"
    assert _expected_gz(TWIST_TO_GZ) not in gz_side, f"{AGAINST_TO_GZ.argument} went ROS->Gazebo"
    crossed = [
        msg
        for msg in run.checker.messages(AGAINST_TO_ROS.topic)
        if not mismatches(TWIST_FROM_GZ_NOT_BRIDGED.ros, msg)
    ]
    assert not crossed, f"{AGAINST_TO_ROS.argument} went Gazebo->ROS"

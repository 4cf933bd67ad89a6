"""The bridge_types CLI: C++ texts and exit codes, plus our additions (--json, services)."""

from __future__ import annotations

import json
import sys

import pytest

from ros_gz_bridge_py.app.bridge_types import PAIRS_HEADING, SERVICES_HEADING, main


def run(capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, str, str]:
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


def test_no_option_prints_nothing(capsys: pytest.CaptureFixture[str]) -> None:
    assert run(capsys) == (0, "", "")


@pytest.mark.parametrize("flag", ["-h", "--help"])
def test_help(capsys: pytest.CaptureFixture[str], flag: str) -> None:
    code, out, _ = run(capsys, flag)
    assert code == 0
    assert "--get-gz-to-ros" in out
    assert "ignition.msgs.X" in out


def test_print_pairs_lists_each_pair_once(capsys: pytest.CaptureFixture[str]) -> None:
    code, out, _ = run(capsys, "--print-pairs")
    assert code == 0
    lines = out.splitlines()
    assert lines[0] == PAIRS_HEADING
    pair_lines = lines[1 : lines.index(SERVICES_HEADING)]
    assert "  - 'geometry_msgs/msg/Twist' (ROS) <=> 'gz.msgs.Twist' (GZ)" in pair_lines
    assert "  - 'sensor_msgs/msg/Imu' (ROS) <=> 'ignition.msgs.IMU' (GZ)" in pair_lines
    assert len(pair_lines) == len(set(pair_lines))
    assert not any("'ignition.msgs.Twist'" in line for line in pair_lines)


def test_print_ros_and_gz_are_sorted_and_unique(capsys: pytest.CaptureFixture[str]) -> None:
    for flag, member in (("--print-ros", "nav_msgs/msg/Odometry"), ("--print-gz", "gz.msgs.Pose")):
        code, out, _ = run(capsys, flag)
        types = out.split()
        assert code == 0
        assert member in types
        assert types == sorted(set(types))


@pytest.mark.parametrize(
    ("flag", "type_name", "expected"),
    [
        ("--get-ros-to-gz", "nav_msgs/msg/Odometry", "gz.msgs.Odometry"),
        ("--get-gz-to-ros", "gz.msgs.Pose", "geometry_msgs/msg/Pose"),
        ("--get-gz-to-ros", "ignition.msgs.Pose", "geometry_msgs/msg/Pose"),
        ("--get-gz-to-ros", "gz.msgs.LaserScan", "sensor_msgs/msg/LaserScan"),
        ("--get-gz-to-ros", "ignition.msgs.IMU", "sensor_msgs/msg/Imu"),
    ],
)
def test_default_lookups(
    capsys: pytest.CaptureFixture[str], flag: str, type_name: str, expected: str
) -> None:
    assert run(capsys, flag, type_name)[:2] == (0, expected + "\n")


@pytest.mark.parametrize(
    ("flag", "listing"), [("--get-ros-to-gz", "--print-ros"), ("--get-gz-to-ros", "--print-gz")]
)
def test_lookup_not_found(capsys: pytest.CaptureFixture[str], flag: str, listing: str) -> None:
    code, out, err = run(capsys, flag, "nope")
    assert (code, out) == (1, "")
    assert f"Type [nope] has no mapping, use {listing} to see supported types" in err


def test_missing_arguments_use_the_cpp_texts(capsys: pytest.CaptureFixture[str]) -> None:
    assert run(capsys, "--get-ros-to-gz") == (1, "", "get-ros-to-gz requires an argument\n")
    assert run(capsys, "--get-gz-to-ros") == (1, "", "--get-gz-to-ros requires an argument\n")


def test_unknown_option_fails(capsys: pytest.CaptureFixture[str]) -> None:
    code, _, err = run(capsys, "--bogus")
    assert code == 1
    assert "--bogus" in err


def test_json_document(capsys: pytest.CaptureFixture[str]) -> None:
    code, out, _ = run(capsys, "--json")
    document = json.loads(out)
    assert code == 0
    assert {
        "ros_type": "std_msgs/msg/Bool",
        "gz_type": "gz.msgs.Boolean",
        "origin": "std_msgs",
        "native_to_ros": True,
        "native_to_gz": True,
        "python_to_ros_because": "",
        "python_to_gz_because": "",
    } in (document["pairs"])
    by_types = {(pair["ros_type"], pair["gz_type"]): pair for pair in document["pairs"]}
    image = by_types[("sensor_msgs/msg/Image", "gz.msgs.Image")]
    assert (image["native_to_ros"], image["native_to_gz"]) == (False, False)
    assert image["python_to_gz_because"] == "a bulk pair (it has its own path)"
    clock = by_types[("rosgraph_msgs/msg/Clock", "gz.msgs.Clock")]
    assert (clock["native_to_ros"], clock["native_to_gz"]) == (True, True)
    assert isinstance(document["services"], list)
    assert isinstance(document["unavailable"], dict)


@pytest.mark.parametrize(
    ("argv", "used", "extra"),
    [
        (["--print-pairs", "--json"], "--print-pairs", "--json"),
        (["--json", "--print-pairs"], "--json", "--print-pairs"),
        (["--print-ros", "a", "b"], "--print-ros", "a b"),
        (
            ["--get-ros-to-gz", "nav_msgs/msg/Odometry", "--json"],
            "--get-ros-to-gz nav_msgs/msg/Odometry",
            "--json",
        ),
    ],
)
def test_arguments_after_the_option_are_refused_not_ignored(
    capsys: pytest.CaptureFixture[str], argv: list[str], used: str, extra: str
) -> None:
    code, out, err = run(capsys, *argv)
    assert (code, out) == (1, "")
    assert err == (
        f"bridge_types: unexpected {extra!r} after {used!r}: give one option per run "
        "(--json alone prints every pair and service as JSON; bridge_types -h lists the options)\n"
    )


@pytest.fixture
def without_ros_gz_interfaces(monkeypatch: pytest.MonkeyPatch) -> str:
    """The interface package not installed; returns the start of the reason given for it."""
    for module in ("ros_gz_interfaces", "ros_gz_interfaces_messages", "ros_gz_interfaces_sensors"):
        monkeypatch.delitem(sys.modules, f"ros_gz_bridge_py.converters.{module}", raising=False)
    monkeypatch.setitem(sys.modules, "ros_gz_interfaces.msg", None)
    monkeypatch.setitem(sys.modules, "ros_gz_interfaces.srv", None)
    return "bridge_types: not listed: the ROS interface package ros_gz_interfaces is not installed"


def test_a_missing_package_is_said_once_in_a_listing(
    capsys: pytest.CaptureFixture[str], without_ros_gz_interfaces: str
) -> None:
    code, out, err = run(capsys, "--print-pairs")
    assert code == 0
    assert "'gz.msgs.Twist'" in out
    assert "ros_gz_interfaces/" not in out
    assert err.count(without_ros_gz_interfaces) == 1, err  # three converter modules, one line


def test_a_lookup_that_finds_its_type_says_nothing_of_missing_packages(
    capsys: pytest.CaptureFixture[str], without_ros_gz_interfaces: str
) -> None:
    assert run(capsys, "--get-ros-to-gz", "tf2_msgs/msg/TFMessage") == (0, "gz.msgs.Pose_V\n", "")
    code, _, err = run(capsys, "--get-ros-to-gz", "ros_gz_interfaces/msg/Contacts")
    assert code == 1
    assert err.startswith(without_ros_gz_interfaces), err

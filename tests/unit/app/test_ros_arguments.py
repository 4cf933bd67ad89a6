"""The ``-p`` names the unknown-parameter warning looks at (``app/ros_arguments.py``)."""

from __future__ import annotations

from pathlib import Path

from ros_gz_bridge_py.app.ros_arguments import _parameter_names
from ros_gz_bridge_py.app.sources import bridge_parameter_problem


def test_only_the_parameters_of_ros_arguments_for_this_node_are_taken() -> None:
    argv = [
        "prog", "-p", "not_ros:=1", "--ros-args", "-p", "lazy:=true", "--param", "a.b:=2",
        "-r", "x:=y", "-p", "me:mine:=3", "-p", "other:theirs:=4", "-p", "*:all:=5",
        "-p", "lazy:=false", "--", "-p", "after:=6", "--ros-args", "--params-file", "f.yaml",
        "-p", "last:=7",
    ]  # fmt: skip
    assert _parameter_names(argv, "me") == ["lazy", "a.b", "mine", "all", "last"]


def test_a_parameters_file_section_for_this_node_is_taken(tmp_path: Path) -> None:
    """--params-file values were not looked at: a misspelt name in the file went unnoticed."""
    params = tmp_path / "bridge.yaml"
    params.write_text(
        "/**:\n  ros__parameters:\n    use_sim_time: true\n    shared: 1\n"
        "ros_gz_bridge:\n  ros__parameters:\n    lazzy: true\n"
        "    qos_overrides:\n      /odom:\n        publisher:\n          depth: 3\n"
        "/robot1/ros_gz_bridge:\n  ros__parameters:\n    in_ns: 1\n"
        "/robot2:\n  ros__parameters:\n    not_a_node: 1\n"
        "  ros_gz_bridge:\n    ros__parameters:\n      nested: 1\n"
        "other_node:\n  ros__parameters:\n    theirs: 1\n"
    )
    argv = ["prog", "--ros-args", "--params-file", str(params), "-p", "lazzy:=false"]
    assert _parameter_names(argv, "ros_gz_bridge", "/ros_gz_bridge") == [
        "lazzy",
        "qos_overrides./odom.publisher.depth",
    ]
    assert _parameter_names(argv, "ros_gz_bridge", "/robot1/ros_gz_bridge") == ["in_ns", "lazzy"]
    assert _parameter_names(argv, "ros_gz_bridge", "/robot2/ros_gz_bridge") == [
        "nested",
        "lazzy",
    ]
    unreadable = ["prog", "--ros-args", "--params-file", str(tmp_path / "none.yaml")]
    assert _parameter_names(unreadable, "ros_gz_bridge", "/ros_gz_bridge") == []


def test_a_bridges_parameter_no_bridge_takes_is_named() -> None:
    """bridges.b3.gz_type_nam was kept by rcl without a word, as was a bridge not listed."""
    names = ["b3", "arm.left"]
    assert bridge_parameter_problem("bridges.b3.gz_type_name", names) == ""
    assert bridge_parameter_problem("bridges.arm.left.lazy", names) == ""
    assert bridge_parameter_problem("qos_overrides./a.publisher.depth", names) == ""
    assert bridge_parameter_problem("bridges.b3.gz_type_nam", names) == (
        "parameter bridges.b3.gz_type_nam is no key of a bridge, so it changes nothing; did you "
        "mean bridges.b3.gz_type_name"
    )
    assert bridge_parameter_problem("bridges.b4.lazy", names) == (
        "parameter bridges.b4.lazy changes nothing: no bridge of bridge_names (b3, arm.left) "
        "has it; add the bridge's name to bridge_names"
    )

"""The ``-p`` names the unknown-parameter warning looks at (``app/ros_arguments.py``)."""

from __future__ import annotations

from ros_gz_bridge_py.app.ros_arguments import _parameter_names


def test_only_the_parameters_of_ros_arguments_for_this_node_are_taken() -> None:
    argv = [
        "prog", "-p", "not_ros:=1", "--ros-args", "-p", "lazy:=true", "--param", "a.b:=2",
        "-r", "x:=y", "-p", "me:mine:=3", "-p", "other:theirs:=4", "-p", "*:all:=5",
        "-p", "lazy:=false", "--", "-p", "after:=6", "--ros-args", "--params-file", "f.yaml",
        "-p", "last:=7",
    ]  # fmt: skip
    assert _parameter_names(argv, "me") == ["lazy", "a.b", "mine", "all", "last"]

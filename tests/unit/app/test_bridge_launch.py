"""ros_gz_bridge's launch arguments, decided without ROS ``launch`` (app/bridge_launch.py), the
launch files' argument tables, and ``bridge_node``'s split of its arguments.

These run everywhere; the same routes under the real launch system are
``tests/bridge/test_launch_e2e.py`` (skipped where launch is not installed).
"""

from __future__ import annotations

import os
import stat
import subprocess
import sys
import sysconfig
import textwrap
import tomllib
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest

from ros_gz_bridge_py.app.bridge_launch import (
    LAUNCH_ARGUMENTS,
    BridgeLaunch,
    LaunchArgumentError,
    as_bool,
    bridge_process,
    extra_parameter_dicts,
    find_bridge_node,
    parse_bridge_params,
)
from ros_gz_bridge_py.app.bridge_node import split_arguments

ROOT = Path(__file__).resolve().parents[3]
XML_LAUNCH_FILE = ROOT / "launch" / "ros_gz_bridge.launch"
#: ros_gz_bridge.launch.py's arguments and defaults (Jazzy; None: must be given), and the
#: bridge_params argument of its later releases.
ROS_GZ_ARGUMENTS = {
    "bridge_name": None,
    "config_file": None,
    "container_name": "ros_gz_container",
    "create_own_container": "False",
    "namespace": "",
    "use_composition": "False",
    "use_respawn": "False",
    "log_level": "info",
    "bridge_params": "",
}


def test_the_launch_arguments_are_ros_gz_bridges_with_its_defaults() -> None:
    assert {a.name: a.default for a in LAUNCH_ARGUMENTS} == ROS_GZ_ARGUMENTS
    assert [a.name for a in LAUNCH_ARGUMENTS] == list(ROS_GZ_ARGUMENTS)


def test_the_launch_file_defaults_are_the_actions_defaults() -> None:
    action = BridgeLaunch(bridge_name="b")
    for argument in LAUNCH_ARGUMENTS:
        if argument.default is None:
            continue
        value = getattr(action, argument.name)
        if isinstance(value, bool):
            assert as_bool(argument.name, argument.default) is value, argument.name
        else:
            assert argument.default == value, argument.name


def test_the_xml_launch_file_declares_the_same_arguments_and_forwards_each_to_the_tag() -> None:
    root = ET.parse(XML_LAUNCH_FILE).getroot()  # noqa: S314 - the repository's own file
    declared = {arg.get("name"): arg.get("default") for arg in root.findall("arg")}
    assert declared == ROS_GZ_ARGUMENTS
    (tag,) = root.findall("ros_gz_bridge_py")
    assert tag.attrib == {name: f"$(var {name})" for name in ROS_GZ_ARGUMENTS}


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        ("True", True), ("true", True), ("1", True), ("on", True), (" yes ", True),
        ("False", False), ("false", False), ("0", False), ("off", False),
        (True, True), (False, False),
    ],
)  # fmt: skip
def test_switches_read_as_launch_reads_booleans(text: str | bool, expected: bool) -> None:
    assert as_bool("use_composition", text) is expected


@pytest.mark.parametrize("text", ["", "maybe", "2", "[true]", "{"])
def test_a_switch_that_is_not_a_boolean_is_named_with_the_fix(text: str) -> None:
    with pytest.raises(LaunchArgumentError, match=r"use_respawn:=.* is not a boolean; give True"):
        as_bool("use_respawn", text)


def test_bridge_params_as_ros_gz_reads_them() -> None:
    text = "'qos_overrides./chatter.publisher.durability': 'transient_local', k2: v2"
    assert parse_bridge_params(text) == {
        "qos_overrides./chatter.publisher.durability": "transient_local",
        "k2": "v2",
    }
    assert parse_bridge_params("") == {}


def test_bridge_params_values_are_typed_as_yaml_scalars() -> None:
    """ros_gz passes each value as text: a boolean or integer parameter would refuse it."""
    text = "{'expand_gz_topic_names': 'true', subscription_heartbeat: 500, max_rate: 2.5}"
    assert parse_bridge_params(text) == {
        "expand_gz_topic_names": True,
        "subscription_heartbeat": 500,
        "max_rate": 2.5,
    }
    assert parse_bridge_params("override_frame_id: 2024-01-01") == {
        "override_frame_id": "2024-01-01"
    }


def test_bridge_params_keep_a_value_with_a_colon_and_skip_an_empty_pair() -> None:
    assert parse_bridge_params("'override_frame_id': 'a:b',") == {"override_frame_id": "a:b"}


@pytest.mark.parametrize(
    ("text", "named"),
    [("lazy", "'lazy'"), ("'lazy' 'true'", "\"'lazy' 'true'\""), ("a: 1, : true", "': true'"),
     ("lazy true", "'lazy true'")],
)  # fmt: skip
def test_a_bridge_params_pair_without_name_and_colon_is_named_with_the_fix(
    text: str, named: str
) -> None:
    """The pair is quoted as written (with its spaces and quotes, which the parse drops:
    'lazy true' was told as 'lazytrue')."""
    with pytest.raises(LaunchArgumentError) as raised:
        parse_bridge_params(text)
    assert str(raised.value).startswith(f"bridge_params: {named} is not NAME: VALUE; write ")


def test_the_default_arguments_start_bridge_node_as_ros_gz_starts_its_own() -> None:
    process = bridge_process(BridgeLaunch("b", config_file="/c.yaml"), "/x/bridge_node")
    assert process.executable == "/x/bridge_node"
    assert process.node_name == "b"
    assert process.namespace == ""
    assert process.config_file == "/c.yaml"
    assert process.bridge_params == {}
    assert process.arguments == ("--ros-args", "--log-level", "info")
    assert not process.respawn
    assert process.respawn_delay == 2.0
    assert process.note == ""


def test_arguments_given_as_launch_text_reach_the_process() -> None:
    launch = BridgeLaunch(
        "b", namespace="robot1", use_respawn="True", log_level="debug",
        bridge_params="'expand_gz_topic_names': 'true'",
    )  # fmt: skip
    process = bridge_process(launch, "bridge_node")
    assert process.namespace == "robot1"
    assert process.respawn
    assert process.arguments == ("--ros-args", "--log-level", "debug")
    assert process.bridge_params == {"expand_gz_topic_names": True}


@pytest.mark.parametrize("own", ["False", "True"])
def test_composition_is_said_in_one_line_and_the_bridge_runs_as_a_process(own: str) -> None:
    launch = BridgeLaunch("b", use_composition="True", create_own_container=own)
    process = bridge_process(launch, "bridge_node")
    assert process.executable == "bridge_node"
    assert "\n" not in process.note
    assert "'b' is a Python node, which a C++ component_container cannot load" in process.note
    assert "runs as its own process (bridge_node) instead" in process.note
    started = "no container 'ros_gz_container' is started"
    loaded = "nothing is loaded into 'ros_gz_container'"
    assert process.note.endswith(started if own == "True" else loaded)


def test_an_empty_bridge_name_or_a_bad_switch_is_named() -> None:
    with pytest.raises(LaunchArgumentError, match="bridge_name is empty"):
        bridge_process(BridgeLaunch(" "), "bridge_node")
    with pytest.raises(LaunchArgumentError, match="use_composition:='yes please'"):
        bridge_process(BridgeLaunch("b", use_composition="yes please"), "bridge_node")
    with pytest.raises(LaunchArgumentError, match="log_level is empty"):
        bridge_process(BridgeLaunch("b", log_level=""), "bridge_node")


def test_extra_bridge_params_take_a_dict_or_a_list_of_dicts() -> None:
    assert extra_parameter_dicts(None) == []
    assert extra_parameter_dicts({"a": 1}) == [{"a": 1}]
    assert extra_parameter_dicts([{"a": 1}, {}]) == [{"a": 1}, {}]
    with pytest.raises(LaunchArgumentError, match="extra_bridge_params must be a dict"):
        extra_parameter_dicts("a: 1")
    with pytest.raises(LaunchArgumentError, match="extra_bridge_params must be a dict"):
        extra_parameter_dicts([{"a": 1}, 2])


def _executable(path: Path) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text("#!/bin/sh\n")
    path.chmod(path.stat().st_mode | stat.S_IXUSR)
    return path


def _prefix(root: Path, *, marker: bool, executable: bool) -> Path:
    """An install prefix with (or without) the package's ament index marker and bridge_node."""
    if marker:
        index = root / "share" / "ament_index" / "resource_index" / "packages"
        index.mkdir(parents=True)
        (index / "ros_gz_bridge_py").write_text("")
    if executable:
        _executable(root / "lib" / "ros_gz_bridge_py" / "bridge_node")
    return root


def test_bridge_node_is_found_where_ros2_run_finds_it(tmp_path: Path) -> None:
    pip_like = _prefix(tmp_path / "venv", marker=True, executable=False)
    colcon = _prefix(tmp_path / "install", marker=True, executable=True)
    env = {"AMENT_PREFIX_PATH": os.pathsep.join([str(pip_like), str(colcon)]), "PATH": ""}
    assert find_bridge_node(env) == str(colcon / "lib" / "ros_gz_bridge_py" / "bridge_node")


def test_without_an_ament_install_bridge_node_is_pips_console_script(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    scripts = _executable(tmp_path / "bin" / "bridge_node").parent
    monkeypatch.setattr(sysconfig, "get_path", lambda _name: str(scripts))
    other = _prefix(tmp_path / "other", marker=False, executable=True)
    env = {"AMENT_PREFIX_PATH": str(other), "PATH": ""}
    assert find_bridge_node(env) == str(scripts / "bridge_node")


def test_bridge_node_on_path_and_nowhere(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(sysconfig, "get_path", lambda _name: str(tmp_path / "no"))
    on_path = _executable(tmp_path / "path" / "bridge_node")
    assert find_bridge_node({"PATH": str(on_path.parent)}) == str(on_path)
    with pytest.raises(LaunchArgumentError, match=r"bridge_node of ros_gz_bridge_py was not found"):
        find_bridge_node({"PATH": str(tmp_path / "empty")})


@pytest.mark.parametrize(
    ("argv", "ros", "others"),
    [
        (["bridge_node"], [], []),
        (["bridge_node", "--ros-args", "-r", "__node:=b"], ["--ros-args", "-r", "__node:=b"], []),
        (
            ["bridge_node", "/a@std_msgs/msg/String[gz.msgs.StringMsg", "--ros-args", "-p",
             "config_file:=c.yaml", "--", "extra"],
            ["--ros-args", "-p", "config_file:=c.yaml", "--"],
            ["/a@std_msgs/msg/String[gz.msgs.StringMsg", "extra"],
        ),
        (
            ["bridge_node", "--ros-args", "--log-level", "debug", "--", "x", "--ros-args", "-r",
             "__ns:=/n"],
            ["--ros-args", "--log-level", "debug", "--", "--ros-args", "-r", "__ns:=/n"],
            ["x"],
        ),
    ],
)  # fmt: skip
def test_bridge_node_keeps_the_ros_arguments_and_sets_the_others_apart(
    argv: list[str], ros: list[str], others: list[str]
) -> None:
    assert split_arguments(argv) == (ros, others)


def test_the_package_and_its_launch_logic_import_without_ros_launch() -> None:
    """In a Python where ``launch`` and ``launch_ros`` cannot be imported (installed or not):
    the package, its entry points' modules and the launch logic import; the actions package
    alone needs launch, and says so by name."""
    script = textwrap.dedent(
        """
        import importlib.abc, sys

        class NoLaunch(importlib.abc.MetaPathFinder):
            def find_spec(self, name, path=None, target=None):
                if name.split(".")[0] in ("launch", "launch_ros"):
                    raise ModuleNotFoundError(f"No module named {name!r}", name=name)
                return None

        sys.meta_path.insert(0, NoLaunch())
        import ros_gz_bridge_py, ros_gz_bridge_py.cli, ros_gz_bridge_py.app.bridge_launch
        import ros_gz_bridge_py.app.bridge_node
        try:
            import ros_gz_bridge_py.actions
        except ModuleNotFoundError as err:
            print("actions:", err.name)
        """
    )
    done = subprocess.run(
        [sys.executable, "-c", script], capture_output=True, text=True, cwd=ROOT, check=False
    )
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == "actions: launch"


def test_the_package_declares_bridge_node_the_tag_and_installs_the_launch_files() -> None:
    project = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]
    assert project["scripts"]["bridge_node"] == "ros_gz_bridge_py.cli:bridge_node_main"
    extensions = project["entry-points"]["launch.frontend.launch_extension"]
    assert extensions == {"ros_gz_bridge_py": "ros_gz_bridge_py.actions"}
    setup_cfg = (ROOT / "setup.cfg").read_text()
    assert (
        "share/ros_gz_bridge_py/launch = launch/ros_gz_bridge.launch.py, "
        "launch/ros_gz_bridge.launch"
    ) in setup_cfg
    for name in ("ros_gz_bridge.launch.py", "ros_gz_bridge.launch"):
        assert (ROOT / "launch" / name).is_file()

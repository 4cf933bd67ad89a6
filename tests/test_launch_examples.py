"""The launch examples are valid Python that names only what this package has.

ROS ``launch`` is not installed here, so the files are compiled and read as syntax trees, never
imported. Checked: every ``Node(...)`` runs an executable of this package (a console script in
pyproject.toml, which colcon installs to lib/ros_gz_bridge_py); every parameter it sets (in
``parameters=[{...}]`` or as ``-p name:=value``) is one that executable declares, read from a
real node that declared the executable's parameters (``app/settings.py``); every ``.yaml`` path
named exists relative to the package root and bridges every entry.
"""

from __future__ import annotations

import ast
import functools
import itertools
import py_compile
import tomllib
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import pytest
import rclpy
from rclpy.context import Context
from rclpy.utilities import try_shutdown

from ros_gz_bridge_py.app import settings
from ros_gz_bridge_py.config import read_yaml_file

pytestmark = [pytest.mark.ros]

ROOT = Path(__file__).resolve().parent.parent
PACKAGE = "ros_gz_bridge_py"
LAUNCH_FILES = sorted((ROOT / "launch_examples").glob("*.launch.py"))
DECLARERS: dict[str, Callable[[Any], object]] = {
    "parameter_bridge": settings.declare_parameter_bridge_parameters,
    "image_bridge": settings.declare_image_bridge_parameters,
}
#: Parameter families the executables accept without declaring each name up front.
PREFIXES = ("qos_overrides.",)


def console_scripts() -> set[str]:
    project = tomllib.loads((ROOT / "pyproject.toml").read_text())
    return set(project["project"]["scripts"])


@functools.cache
def declared_parameters(executable: str) -> frozenset[str]:
    """The names a real node has after declaring the executable's parameters."""
    context = Context()
    rclpy.init(context=context)
    try:
        node = rclpy.create_node(f"launch_check_{executable}", context=context)
        try:
            DECLARERS[executable](node)
            return frozenset(node.list_parameters([], 0).names)
        finally:
            node.destroy_node()
    finally:
        try_shutdown(context=context)


def node_calls(tree: ast.AST) -> Iterator[ast.Call]:
    for call in ast.walk(tree):
        if (
            isinstance(call, ast.Call)
            and isinstance(call.func, ast.Name)
            and call.func.id == "Node"
        ):
            yield call


def keyword(call: ast.Call, name: str) -> ast.expr | None:
    return next((kw.value for kw in call.keywords if kw.arg == name), None)


def parameter_names(call: ast.Call) -> list[str]:
    """Keys of ``parameters=[{...}]`` dicts and ``-p name:=value`` in argument lists."""
    names: list[str] = []
    parameters = keyword(call, "parameters")
    for node in ast.walk(parameters) if parameters is not None else ():
        if isinstance(node, ast.Dict):
            names += [str(k.value) for k in node.keys if isinstance(k, ast.Constant)]
    for argument_list in (keyword(call, "arguments"), keyword(call, "ros_arguments")):
        if isinstance(argument_list, ast.List):
            items = [e.value if isinstance(e, ast.Constant) else None for e in argument_list.elts]
            names += [
                str(value).split(":=", 1)[0]
                for flag, value in itertools.pairwise(items)
                if flag in ("-p", "--param")
            ]
    return names


def yaml_paths(tree: ast.AST) -> list[str]:
    return [
        node.value
        for node in ast.walk(tree)
        if isinstance(node, ast.Constant)
        and isinstance(node.value, str)
        and node.value.endswith(".yaml")
    ]


def test_there_are_launch_examples() -> None:
    names = {path.name for path in LAUNCH_FILES}
    assert {
        "turtlebot3_bridge.launch.py",
        "camera_image_bridge.launch.py",
        "multi_robot_bridge.launch.py",
    } <= names


@pytest.mark.parametrize("path", LAUNCH_FILES, ids=lambda p: p.name)
def test_launch_file_compiles_and_defines_generate_launch_description(
    path: Path, tmp_path: Path
) -> None:
    py_compile.compile(str(path), cfile=str(tmp_path / "out.pyc"), doraise=True)
    tree = ast.parse(path.read_text())
    functions = {n.name for n in tree.body if isinstance(n, ast.FunctionDef)}
    assert "generate_launch_description" in functions


@pytest.mark.parametrize("path", LAUNCH_FILES, ids=lambda p: p.name)
def test_nodes_run_executables_of_this_package_with_declared_parameters(path: Path) -> None:
    tree = ast.parse(path.read_text())
    calls = list(node_calls(tree))
    assert calls, f"{path.name} starts no Node"
    scripts = console_scripts()
    for call in calls:
        package = keyword(call, "package")
        executable = keyword(call, "executable")
        assert isinstance(package, ast.Constant)
        assert package.value == PACKAGE
        assert isinstance(executable, ast.Constant)
        assert executable.value in scripts
        assert executable.value in DECLARERS, f"no parameter list for {executable.value}"
        declared = declared_parameters(executable.value)
        for name in parameter_names(call):
            assert name in declared or name.startswith(PREFIXES), (
                f"{path.name}: {executable.value} has no parameter {name!r}; "
                f"it declares {sorted(declared)}"
            )


@pytest.mark.parametrize("path", LAUNCH_FILES, ids=lambda p: p.name)
def test_config_files_exist_and_bridge_every_entry(path: Path) -> None:
    for relative in yaml_paths(ast.parse(path.read_text())):
        config = ROOT / relative
        assert config.is_file(), f"{path.name} names {relative}, missing from the repository"
        result = read_yaml_file(str(config))
        assert not result.errors, result.errors
        assert result.specs


def test_the_multi_robot_example_bridges_clock_once() -> None:
    tree = ast.parse((ROOT / "launch_examples" / "multi_robot_bridge.launch.py").read_text())
    clock_arguments = [
        node.value
        for node in ast.walk(tree)
        if isinstance(node, ast.Constant)
        and isinstance(node.value, str)
        and node.value.startswith("/clock@")
    ]
    assert len(clock_arguments) == 1
    for relative in yaml_paths(tree):
        specs = read_yaml_file(str(ROOT / relative)).specs
        assert all("clock" not in getattr(spec, "ros_topic", "") for spec in specs)

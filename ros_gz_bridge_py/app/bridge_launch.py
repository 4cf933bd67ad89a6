"""What ros_gz_bridge's launch arguments start here, decided without ROS ``launch``.

``launch/ros_gz_bridge.launch.py``, the ``RosGzBridge`` action (:mod:`ros_gz_bridge_py.actions`)
and its ``<ros_gz_bridge_py>`` tag take ros_gz_bridge's (Jazzy) arguments. The action performs
their substitutions and hands the text here; :func:`bridge_process` answers with the one process
to start: ``bridge_node`` (:mod:`ros_gz_bridge_py.app.bridge_node`) named ``bridge_name``, with
``config_file`` and the extra parameters, at ``log_level``. ``launch`` is an optional dependency,
so this module imports none of it (tested without it).

Composition: ros_gz loads its C++ ``RosGzBridge`` component into an ``rclcpp_components``
container when ``use_composition`` is true. A C++ container cannot load a Python node, so the
bridge runs as its own process then too, and :attr:`BridgeProcess.note` says so in one line.
What ros_gz does with each argument: docs/behaviour.md §1.3.
"""

from __future__ import annotations

import os
import shutil
import sysconfig
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

import yaml

PACKAGE = "ros_gz_bridge_py"
EXECUTABLE = "bridge_node"
#: Seconds before a respawn, as ros_gz.
RESPAWN_DELAY = 2.0
#: The characters ros_gz deletes from ``bridge_params`` before splitting it.
_DROPPED_FROM_BRIDGE_PARAMS = str.maketrans("", "", "{} \"'")


#: A parameter value read from text.
Scalar = str | bool | int | float


class LaunchArgumentError(ValueError):
    """A launch argument that cannot be used; the message names it and the fix."""


@dataclass(frozen=True)
class LaunchArgument:
    """A launch argument of ``ros_gz_bridge.launch.py``: its name, default and description."""

    name: str
    #: None: the argument must be given.
    default: str | None
    description: str


#: ros_gz_bridge.launch.py's arguments (Jazzy), in its order, with its defaults.
LAUNCH_ARGUMENTS = (
    LaunchArgument("bridge_name", None, "Name of the bridge node"),
    LaunchArgument("config_file", None, "YAML config file"),
    LaunchArgument(
        "container_name",
        "ros_gz_container",
        "Name of the container the C++ bridge would load into with use_composition "
        "(this bridge is Python: it runs as its own process)",
    ),
    LaunchArgument(
        "create_own_container",
        "False",
        "Whether the C++ bridge would start its own container with use_composition "
        "(this bridge starts none)",
    ),
    LaunchArgument("namespace", "", "Top-level namespace"),
    LaunchArgument(
        "use_composition",
        "False",
        "Use composed bringup if True (this bridge is Python: it says so once and runs as its "
        "own process)",
    ),
    LaunchArgument("use_respawn", "False", "Whether to respawn if the bridge process ends"),
    LaunchArgument("log_level", "info", "log level"),
    LaunchArgument(
        "bridge_params",
        "",
        "Extra parameters to pass to the bridge, e.g. \"'expand_gz_topic_names': 'true'\"",
    ),
)


@dataclass(frozen=True)
class BridgeLaunch:
    """The launch arguments with their substitutions performed; the defaults are ros_gz's
    action's (where the launch file has none: ``config_file`` may be left out here)."""

    bridge_name: str
    config_file: str = ""
    container_name: str = "ros_gz_container"
    create_own_container: bool | str = False
    namespace: str = ""
    use_composition: bool | str = False
    use_respawn: bool | str = False
    log_level: str = "info"
    bridge_params: str = ""


@dataclass(frozen=True)
class BridgeProcess:
    """The process to start for a :class:`BridgeLaunch`."""

    executable: str
    node_name: str
    namespace: str
    config_file: str
    #: ``bridge_params``, parsed: set after ``config_file``, before ``extra_bridge_params``.
    bridge_params: Mapping[str, Scalar]
    #: The ROS arguments (the log level).
    arguments: tuple[str, ...]
    respawn: bool
    respawn_delay: float = RESPAWN_DELAY
    #: One line for the launch log, or "".
    note: str = ""


def as_bool(name: str, value: bool | str) -> bool:
    """``value`` of the argument ``name`` as launch reads a boolean: ``1``/``0`` or a YAML
    boolean (``True``, ``false``, ``on`` ...).

    Raises:
        LaunchArgumentError: anything else.
    """
    if isinstance(value, bool):
        return value
    text = {"1": "true", "0": "false"}.get(value.strip(), value.strip())
    try:
        parsed = yaml.safe_load(text) if text else None
    except yaml.YAMLError:
        parsed = None
    if not isinstance(parsed, bool):
        msg = f"{name}:={value!r} is not a boolean; give True or False"
        raise LaunchArgumentError(msg)
    return parsed


def parse_bridge_params(text: str) -> dict[str, Scalar]:
    """``bridge_params`` as ros_gz reads it: braces, quotes and spaces dropped, then
    ``NAME: VALUE`` pairs separated by commas. Unlike ros_gz, each value is read as a YAML
    scalar (``true`` a boolean, ``500`` an integer; ros_gz passes every value as text, which a
    boolean or integer parameter refuses), a value may hold a colon (the first one separates),
    and an empty pair (a trailing comma) is skipped.

    Raises:
        LaunchArgumentError: a pair without a colon or without a name.
    """
    params: dict[str, Scalar] = {}
    for written in text.split(","):  # the dropped characters hold no comma
        pair = written.translate(_DROPPED_FROM_BRIDGE_PARAMS)
        if not pair:
            continue
        name, colon, value = pair.partition(":")
        if not colon or not name:
            msg = (
                f"bridge_params: {written.strip()!r} is not NAME: VALUE; write the parameters "
                "as \"'name1': 'value1', 'name2': 'value2'\""
            )
            raise LaunchArgumentError(msg)
        params[name] = _scalar(value)
    return params


def _scalar(text: str) -> Scalar:
    """``text`` as a YAML scalar (a boolean, integer, float or text), else as it is."""
    try:
        value = yaml.safe_load(text)
    except yaml.YAMLError:
        return text
    return value if isinstance(value, bool | int | float | str) else text


def composition_note(launch: BridgeLaunch) -> str:
    """The line to log when ``use_composition`` asks for a component, else ""."""
    if not as_bool("use_composition", launch.use_composition):
        return ""
    if as_bool("create_own_container", launch.create_own_container):
        container = f"no container {launch.container_name!r} is started"
    else:
        container = f"nothing is loaded into {launch.container_name!r}"
    return (
        f"use_composition:=True: {launch.bridge_name!r} is a Python node, which a C++ "
        f"component_container cannot load; it runs as its own process ({EXECUTABLE}) instead, "
        f"and {container}"
    )


def bridge_process(launch: BridgeLaunch, executable: str) -> BridgeProcess:
    """The ``bridge_node`` process (at ``executable``) that ``launch`` asks for.

    Raises:
        LaunchArgumentError: an argument that cannot be used (named in the message).
    """
    if not launch.bridge_name.strip():
        msg = "bridge_name is empty; give the bridge node a name (bridge_name:=<name>)"
        raise LaunchArgumentError(msg)
    if not launch.log_level.strip():
        msg = "log_level is empty; give one of debug, info, warn, error, fatal"
        raise LaunchArgumentError(msg)
    return BridgeProcess(
        executable=executable,
        node_name=launch.bridge_name,
        namespace=launch.namespace,
        config_file=launch.config_file,
        bridge_params=parse_bridge_params(launch.bridge_params),
        arguments=("--ros-args", "--log-level", launch.log_level),
        respawn=as_bool("use_respawn", launch.use_respawn),
        note=composition_note(launch),
    )


def extra_parameter_dicts(extra: object) -> list[Mapping[str, object]]:
    """``extra_bridge_params`` as a list of parameter dicts: None, a dict, or a list of dicts
    (launch files pass ``[{...}]`` as well as ``{...}``).

    Raises:
        LaunchArgumentError: anything else.
    """
    if extra is None:
        return []
    if isinstance(extra, Mapping):
        return [extra]
    if (
        isinstance(extra, Sequence)
        and not isinstance(extra, str)
        and all(isinstance(item, Mapping) for item in extra)
    ):
        return list(extra)
    msg = (
        f"extra_bridge_params must be a dict of parameters (or a list of dicts), not "
        f"{type(extra).__name__}: {extra!r}"
    )
    raise LaunchArgumentError(msg)


def find_bridge_node(env: Mapping[str, str] | None = None) -> str:
    """The ``bridge_node`` to start: where ``ros2 run`` finds it (``lib/ros_gz_bridge_py`` of
    the first ``AMENT_PREFIX_PATH`` prefix that has the package: a colcon install), else the
    console script that pip put beside this interpreter, else one on ``PATH``.

    Raises:
        LaunchArgumentError: none of these (the message says how to install it).
    """
    env = os.environ if env is None else env
    for prefix in filter(None, env.get("AMENT_PREFIX_PATH", "").split(os.pathsep)):
        marker = Path(prefix, "share", "ament_index", "resource_index", "packages", PACKAGE)
        candidate = Path(prefix, "lib", PACKAGE, EXECUTABLE)
        if marker.is_file() and os.access(candidate, os.X_OK):
            return str(candidate)
    scripts = Path(sysconfig.get_path("scripts"), EXECUTABLE)
    if os.access(scripts, os.X_OK):
        return str(scripts)
    on_path = shutil.which(EXECUTABLE, path=env.get("PATH"))
    if on_path is not None:
        return on_path
    msg = (
        f"{EXECUTABLE} of {PACKAGE} was not found: not in lib/{PACKAGE} of an AMENT_PREFIX_PATH "
        f"prefix, nor in {scripts.parent}, nor on PATH. Install {PACKAGE} (pip install, or "
        "colcon build and source install/setup.bash)"
    )
    raise LaunchArgumentError(msg)

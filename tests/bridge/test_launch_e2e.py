"""ros_gz_bridge's launch routes under the real ROS launch system, each bridging end to end.

The launch file (``launch/ros_gz_bridge.launch.py`` as ros_gz's is used: ``bridge_name:=b
config_file:=<seed TurtleBot3 file>``), the ``RosGzBridge`` action from Python, and the
``<ros_gz_bridge_py>`` tag in an XML and a YAML launch file: each started by
``launch_runner.py`` (what ``ros2 launch`` does), with Fortress peers (Debian ign-transport 11)
on the Gazebo side and an rclpy checker on the ROS side, and ended by SIGINT, after which every
process must have finished cleanly.

ROS launch has no wheels and ``make setup`` does not install it (nor does CI): where
``launch`` and ``launch_ros`` are not importable, the module is skipped in one line. How to run
it: README.md, Development.
"""

from __future__ import annotations

import importlib.metadata
import importlib.util
import json
import os
import signal
import sys
from collections.abc import Iterator
from pathlib import Path

import pytest

from testing.e2e_harness import (
    RUN_TIMEOUT,
    GzEcho,
    ProcessGroup,
    RosChecker,
    parse_gz,
    wait_all,
)
from testing.gzpeer import ROOT, PeerProcess
from tests.bridge.e2e_values import CLOCK, ODOMETRY, TWIST_TO_GZ, GzSample, mismatches


def launch_problem() -> str | None:
    """Why ROS launch cannot be used here, or None. (Without it, ``import launch`` finds the
    repository's ``launch/`` folder as a namespace package: no origin.)"""
    for name in ("launch", "launch_ros"):
        spec = importlib.util.find_spec(name)
        if spec is None or spec.origin is None:
            return f"no package {name!r}"
    return None


LAUNCH_PROBLEM = launch_problem()
if LAUNCH_PROBLEM is not None:
    pytest.skip(
        f"ROS launch is not importable ({LAUNCH_PROBLEM}); README.md, Development, says how "
        "to run these tests",
        allow_module_level=True,
    )

pytestmark = [pytest.mark.peer, pytest.mark.ros, pytest.mark.slow]

RUNNER = Path(__file__).resolve().parent / "launch_runner.py"
LAUNCH_FILE = ROOT / "launch" / "ros_gz_bridge.launch.py"
SEED_CONFIG = Path("/work/shared/data/configs/turtlebot3_waffle_bridge.yaml")
#: Entries of the seed file (8 topics, one direction each).
SEED_ENTRIES = 8
ODOM_ENTRY = """\
- ros_topic_name: "odom"
  gz_topic_name: "odom"
  ros_type_name: "nav_msgs/msg/Odometry"
  gz_type_name: "gz.msgs.Odometry"
  direction: GZ_TO_ROS
"""
#: Seconds a launch has to end after SIGINT (its processes stop in turn on a busy machine).
STOP_TIMEOUT = 60.0


def launch_prefix() -> str | None:
    """The install prefix of launch's frontend grammar, where pip put launch (wheels, or a
    ``--prefix`` install): the frontends look it up in the ament index, so it must be on
    ``AMENT_PREFIX_PATH`` (a sourced Jazzy has it there already). None: not installed so."""
    for file in importlib.metadata.files("launch") or ():
        if file.as_posix().endswith("share/launch/frontend/grammar.lark"):
            return str(Path(str(file.locate())).resolve().parents[3])
    return None


def launch_environment() -> dict[str, str]:
    env = dict(os.environ)
    prefix = launch_prefix()
    paths = env.get("AMENT_PREFIX_PATH", "").split(os.pathsep)
    if prefix is not None and prefix not in paths:
        env["AMENT_PREFIX_PATH"] = os.pathsep.join(filter(None, [prefix, *paths]))
    return env


def start_launch(group: ProcessGroup, *args: str) -> PeerProcess:
    """``launch_runner.py ARGS``: a launch file with its arguments, or ``--action JSON``."""
    return group.start([sys.executable, str(RUNNER), *args], launch_environment())


def stop_cleanly(runner: PeerProcess) -> str:
    """SIGINT, as Ctrl-C in ``ros2 launch``; the launch must end with status 0, its bridge
    process finished cleanly on that SIGINT (launch sends SIGTERM after 5 s) and no traceback
    anywhere. Returns the whole output."""
    runner.send_signal(signal.SIGINT)
    runner.wait(STOP_TIMEOUT)
    output = runner.output()
    assert runner.returncode == 0, output
    assert "Traceback" not in output, output
    assert "process has finished cleanly" in output, output
    assert "escalating to 'SIGTERM'" not in output, output
    return output


def arrived(checker: RosChecker, topic: str, sample: GzSample) -> bool:
    return any(not mismatches(sample.ros, msg) for msg in checker.messages(topic))


def wait_for_ros(checker: RosChecker, expected: dict[str, GzSample], runner: PeerProcess) -> None:
    """Every ROS topic of ``expected`` receives its sample converted."""
    checks = {
        topic: (lambda t=topic, s=sample: arrived(checker, t, s))
        for topic, sample in expected.items()
    }
    held = wait_all(checks, RUN_TIMEOUT)
    assert all(held.values()), f"arrived: {held}; launch output:\n{runner.output()}"


@pytest.fixture
def group() -> Iterator[ProcessGroup]:
    started = ProcessGroup()
    yield started
    started.stop()


def config_file(tmp_path: Path, text: str) -> str:
    path = tmp_path / "bridge.yaml"
    path.write_text(text)
    return str(path)


def test_the_launch_file_as_ros_gz_documents_it_bridges_the_seed_config(
    group: ProcessGroup,
) -> None:
    """``ros2 launch <package> ros_gz_bridge.launch.py bridge_name:=b config_file:=seed``."""
    runner = start_launch(group, str(LAUNCH_FILE), "bridge_name:=b", f"config_file:={SEED_CONFIG}")
    group.peer(*ODOMETRY.peer_pub_args("/odom"))
    echo = GzEcho.peer(group, "/cmd_vel", "Twist", "ignition.msgs.Twist")
    checker = RosChecker(
        group, [("/odom", "nav_msgs/msg/Odometry")], [("/cmd_vel", TWIST_TO_GZ.ros_type,
                                                       TWIST_TO_GZ.values)]
    )  # fmt: skip
    wait_for_ros(checker, {"/odom": ODOMETRY}, runner)
    expected = parse_gz("Twist", TWIST_TO_GZ.gz_text)
    wait_all({"cmd_vel": lambda: expected in echo.messages()}, RUN_TIMEOUT)
    assert expected in echo.messages(), runner.output()
    output = stop_cleanly(runner)
    created = [line for line in output.splitlines() if "[b]: Creating" in line]
    assert len(created) == SEED_ENTRIES, output
    assert "[bridge_node-1]" in output


def test_the_action_with_composition_runs_the_bridge_and_says_so_once(
    group: ProcessGroup, tmp_path: Path
) -> None:
    """``RosGzBridge(...)`` from Python: a namespace, ``extra_bridge_params`` expanding the
    Gazebo names into it, and ``use_composition=True`` (one line, then a process)."""
    action = {
        "bridge_name": "action_bridge",
        "config_file": config_file(tmp_path, ODOM_ENTRY),
        "namespace": "robot1",
        "use_composition": True,
        "create_own_container": "True",
        "extra_bridge_params": {"expand_gz_topic_names": True},
    }
    runner = start_launch(group, "--action", json.dumps(action))
    group.peer(*ODOMETRY.peer_pub_args("/robot1/odom"))
    checker = RosChecker(group, [("/robot1/odom", "nav_msgs/msg/Odometry")])
    wait_for_ros(checker, {"/robot1/odom": ODOMETRY}, runner)
    output = stop_cleanly(runner)
    notes = [line for line in output.splitlines() if "component_container cannot load" in line]
    assert len(notes) == 1, output
    assert "no container 'ros_gz_container' is started" in notes[0]


def test_the_xml_tag_bridges_its_config_file_and_its_topic_children(
    group: ProcessGroup, tmp_path: Path
) -> None:
    xml = tmp_path / "bridge.launch.xml"
    xml.write_text(
        f"""<launch>
  <arg name="config" default="{config_file(tmp_path, ODOM_ENTRY)}" />
  <ros_gz_bridge_py bridge_name="xml_bridge" config_file="$(var config)" log_level="debug">
    <topic ros_topic_name="/clock" gz_topic_name="/clock" ros_type_name="rosgraph_msgs/msg/Clock"
           gz_type_name="gz.msgs.Clock" direction="GZ_TO_ROS" />
  </ros_gz_bridge_py>
</launch>
"""
    )
    runner = start_launch(group, str(xml))
    group.peer(*ODOMETRY.peer_pub_args("/odom"))
    group.peer(*CLOCK.peer_pub_args("/clock"))
    checker = RosChecker(
        group, [("/odom", "nav_msgs/msg/Odometry"), ("/clock", "rosgraph_msgs/msg/Clock")]
    )
    wait_for_ros(checker, {"/odom": ODOMETRY, "/clock": CLOCK}, runner)
    output = stop_cleanly(runner)
    assert "[DEBUG]" in output, output
    assert "[xml_bridge]: Creating GZ->ROS Bridge: [/clock" in output, output


def test_the_yaml_tag_bridges_with_bridge_params(group: ProcessGroup, tmp_path: Path) -> None:
    """``bridge_params`` as text (ros_gz's form), expanding the Gazebo names into the
    namespace."""
    yaml_file = tmp_path / "bridge.launch.yaml"
    yaml_file.write_text(
        f"""launch:
- ros_gz_bridge_py:
    bridge_name: yaml_bridge
    config_file: {config_file(tmp_path, ODOM_ENTRY)}
    namespace: tb3
    bridge_params: "'expand_gz_topic_names': 'true'"
"""
    )
    runner = start_launch(group, str(yaml_file))
    group.peer(*ODOMETRY.peer_pub_args("/tb3/odom"))
    checker = RosChecker(group, [("/tb3/odom", "nav_msgs/msg/Odometry")])
    wait_for_ros(checker, {"/tb3/odom": ODOMETRY}, runner)
    output = stop_cleanly(runner)
    assert "[tb3.yaml_bridge]: Creating GZ->ROS Bridge: [/tb3/odom" in output, output

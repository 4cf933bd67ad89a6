"""``parameter_bridge`` on the command line: help, usage errors, and entries it cannot bridge.

Usage errors end the process before ROS starts, like the C++ bridge (usage on stdout, status
255), and add one line on stderr naming the argument and what is wrong with it.
"""

from __future__ import annotations

import subprocess
from pathlib import Path

import pytest

from ros_gz_bridge_py.config import USAGE
from ros_gz_bridge_py.transport import GzNode
from testing.behaviour_harness import (
    STRING,
    WAIT,
    bridge_command,
    gz_node,
    start_bridge,
    started,
)
from testing.gzpeer import PeerProcess, require_peer, unique_name, wait_for_line, wait_until

__all__ = ["gz_node", "started"]

USAGE_EXIT = 255


def run(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        bridge_command(*args), capture_output=True, text=True, timeout=30, check=False
    )


@pytest.mark.parametrize("flag", ["-h", "--help"])
def test_help_prints_usage_and_succeeds(flag: str) -> None:
    done = run(flag)
    assert done.returncode == 0
    assert done.stdout.strip() == USAGE.strip()
    assert "topic@ROS2_type@Gz_type" in done.stdout


def test_no_arguments_prints_usage_and_fails() -> None:
    done = run()
    assert done.returncode == USAGE_EXIT
    assert done.stdout.strip() == USAGE.strip()


@pytest.mark.parametrize(
    ("args", "position", "problem"),
    [
        (["chatter"], 1, "no '@'"),
        (["@a@b"], 1, "no topic or service name"),
        (
            ["/w/control@ros_gz_interfaces/srv/ControlWorld@gz.msgs.WorldControl"],
            1,
            "both Gazebo types or neither",
        ),
        (
            ["/w/control@ros_gz_interfaces/srv/ControlWorld[gz.msgs.WorldControl"],
            1,
            "no direction symbol",
        ),
        (["t@A@B@C"], 1, "more than one '@'"),
        (["t@A@"], 1, "no Gazebo type after the direction symbol"),
        (["t@A["], 1, "no Gazebo type after the direction symbol"),
        # C++ bridges nothing here, silently.
        (["/t@std_msgs/msg/String"], 1, "no Gazebo type"),
        (["/ok@std_msgs/msg/String@gz.msgs.StringMsg", "/t@std_msgs/msg/String["], 2, "no "),
    ],
)
def test_bad_argument_prints_usage_and_names_it(
    args: list[str], position: int, problem: str
) -> None:
    done = run(*args)
    assert done.returncode == USAGE_EXIT
    assert done.stdout.strip() == USAGE.strip()
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 1, done.stderr
    assert f"argument {position} '{args[position - 1]}'" in lines[0]
    assert problem in lines[0]


@pytest.mark.ros
@pytest.mark.peer
def test_a_parameter_of_the_wrong_type_stops_with_one_error_and_no_traceback() -> None:
    done = run("/t@std_msgs/msg/String[gz.msgs.StringMsg", "--ros-args",
               "-p", "expand_gz_topic_names:=maybe")  # fmt: skip
    assert done.returncode == USAGE_EXIT
    assert "Traceback" not in done.stderr
    assert (
        "parameter expand_gz_topic_names has the wrong type (Trying to set parameter "
        "'expand_gz_topic_names' to 'maybe' of type 'STRING', expecting type 'BOOL'); give it "
        "as true or false, or leave it out"
    ) in done.stderr


def test_unsupported_pair_is_reported_and_the_other_bridges_run(
    gz_node: GzNode, started: list[PeerProcess]
) -> None:
    require_peer()
    wrong = unique_name("cli_wrong")
    good = unique_name("cli_good")
    bridge = start_bridge(
        f"{wrong}@std_msgs/String@gz.msgs.StringMsg", f"{good}@std_msgs/msg/String[{STRING}"
    )
    started.append(bridge)
    error = wait_for_line(bridge, r"\[ERROR\].*Failed to create a bridge", timeout=30).string
    assert "argument 1" in error
    assert f"topic [{wrong}] with ROS2 type [std_msgs/String]" in error
    assert "did you mean [std_msgs/msg/String]" in error

    publisher = gz_node.advertise(good, STRING)
    try:
        wait_until(publisher.has_connections, WAIT, "the valid bridge's Gazebo subscription")
    finally:
        publisher.close()
    assert bridge.poll() is None


def test_when_every_entry_fails_the_warning_says_so(started: list[PeerProcess]) -> None:
    """It said 'give topic arguments, or -p config_file...' to a user who had given some."""
    topic = unique_name("cli_all_wrong")
    bridge = start_bridge(f"{topic}@std_msgs/msg/String@gz.msgs.Twist")
    started.append(bridge)
    wait_for_line(bridge, r"\[ERROR\].*Failed to create a bridge", timeout=30)
    warning = wait_for_line(bridge, r"\[WARN\].*No bridges are running", timeout=WAIT).string
    assert warning.endswith(
        "No bridges are running: no entry could be bridged (1 failed; the errors above say "
        "why and what to write)"
    )
    # a config file that cannot be read is a failure too, not a file never given
    unread = start_bridge(ros_args=["-p", f"config_file:=/{unique_name('absent')}.yaml"])
    started.append(unread)
    warning = wait_for_line(unread, r"\[WARN\].*No bridges are running", timeout=WAIT).string
    assert warning.endswith(
        "no entry could be bridged (1 failed; the errors above say why and what to write)"
    )


def test_a_misspelt_parameter_is_named_with_the_one_meant(started: list[PeerProcess]) -> None:
    """rcl keeps any -p value without a word: 'lazzy:=true' left lazy false unnoticed."""
    topic = unique_name("cli_misspelt")
    bridge = start_bridge(
        f"{topic}@std_msgs/msg/String[{STRING}",
        ros_args=[
            "-p", "other_node:lazzy:=true",  # another node's: not ours to judge
            "-p", f"qos_overrides.{topic}.publisher.depth:=3",  # declared with its topic
            "-p", "ros_gz_bridge:lazzy:=true",
        ],
    )  # fmt: skip
    started.append(bridge)
    warning = wait_for_line(bridge, r"\[WARN\].*lazzy", timeout=30).string
    assert warning.endswith(
        "parameter lazzy is none of parameter_bridge's, so it changes nothing; did you mean lazy"
    )
    assert bridge.output().count("is none of parameter_bridge's") == 1


def test_a_misspelt_parameter_in_a_params_file_is_named(
    started: list[PeerProcess], tmp_path: Path
) -> None:
    """A --params-file value rcl keeps without a word, as a -p one: the file's section for the
    bridge by name is looked at; its wildcard section, which launch files share, is not."""
    topic = unique_name("cli_params_file")
    params = tmp_path / "bridge.yaml"
    params.write_text(
        "/**:\n  ros__parameters:\n    shared_with_others: 1\n"
        "ros_gz_bridge:\n  ros__parameters:\n    status_priod: 2.0\n"
        f"    qos_overrides:\n      {topic}:\n        publisher:\n          depth: 3\n"
    )
    bridge = start_bridge(
        f"{topic}@std_msgs/msg/String[{STRING}", ros_args=["--params-file", str(params)]
    )
    started.append(bridge)
    warning = wait_for_line(bridge, r"\[WARN\].*status_priod", timeout=30).string
    assert warning.endswith(
        "parameter status_priod is none of parameter_bridge's, so it changes nothing; "
        "did you mean status_period"
    )
    assert bridge.output().count("is none of parameter_bridge's") == 1


def test_a_bridges_parameter_no_bridge_takes_is_named(
    started: list[PeerProcess], tmp_path: Path
) -> None:
    """A misspelt key of a bridges.<name> block in a parameters file changed nothing, unsaid."""
    topic = unique_name("cli_bridges_key")
    params = tmp_path / "bridges.yaml"
    params.write_text(
        "ros_gz_bridge:\n  ros__parameters:\n    bridge_names: [b3]\n    bridges:\n"
        f"      b3:\n        ros_topic_name: {topic}\n        gz_topic_name: {topic}\n"
        f"        ros_type_name: std_msgs/msg/String\n        gz_type_name: {STRING}\n"
        "        directon: GZ_TO_ROS\n"
    )
    bridge = start_bridge(ros_args=["--params-file", str(params)])
    started.append(bridge)
    warning = wait_for_line(bridge, r"\[WARN\].*bridges\.b3\.directon", timeout=30).string
    assert warning.endswith(
        "parameter bridges.b3.directon is no key of a bridge, so it changes nothing; did you "
        "mean bridges.b3.direction"
    )

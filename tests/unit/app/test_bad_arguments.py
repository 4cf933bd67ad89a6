"""Bad ROS arguments and refused parameters end each executable with one line, never a
traceback, and the exit status of its other bad arguments (255, as the C++ bridge).

The real console scripts run here: rclpy raised these errors from ``rclpy.init`` and
``remove_ros_args``, and the transport's from the bridge's creation, past every handler.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import threading
from pathlib import Path

import pytest

from ros_gz_bridge_py.app.ros_arguments import ros_arguments_problem
from ros_gz_bridge_py.app.settings import TRANSPORT_IMPLEMENTATION_ENV

USAGE_EXIT = 255
#: The console scripts of the venv running the tests (beside the interpreter).
BIN = Path(sys.prefix) / "bin"
TOPIC = "/chatter@std_msgs/msg/String@gz.msgs.StringMsg"
#: What each executable takes as a topic argument.
TOPICS = {"parameter_bridge": TOPIC, "image_bridge": "/cam", "bridge_node": TOPIC}
MISPLACED = "put {program}'s own arguments before --ros-args, or after a -- that ends the ROS"


def run(program: str, *args: str, env: dict[str, str] | None = None) -> tuple[int, list[str]]:
    """(exit status, the lines on stderr but rcl's warnings about ROS_LOCALHOST_ONLY and the
    bridge's INFO lines: on a busy machine it may first say that it removed the shared-memory
    segments of processes killed before it)."""
    done = subprocess.run(
        [str(BIN / program), *args],
        capture_output=True,
        text=True,
        timeout=30,
        check=False,
        env={**os.environ, **(env or {})},
    )
    lines = [
        line for line in done.stderr.splitlines() if "[rcl]:" not in line and "[INFO]" not in line
    ]
    return done.returncode, lines


def test_a_bridge_list_given_as_a_parameters_file_is_sent_to_config_file(
    tmp_path: Path,
) -> None:
    """rcl said 'Sequences cannot be key' and the fix asked for a readable file."""
    bridges = tmp_path / "bridge.yaml"
    bridges.write_text(
        "- ros_topic_name: chatter\n  gz_topic_name: chatter\n"
        "  ros_type_name: std_msgs/msg/String\n  gz_type_name: gz.msgs.StringMsg\n"
    )
    problem = ros_arguments_problem(
        "parameter_bridge", ["pb", "--ros-args", "--params-file", str(bridges)]
    )
    assert problem.endswith(
        "; that file is a list of bridges, not a parameters file: give it as "
        f"-p config_file:={bridges}"
    )


@pytest.mark.parametrize(
    ("ros_args", "named", "fix"),
    [
        (["-p", "config_file"], "'-p config_file'", "write -p NAME:=VALUE with a value"),
        (["-p", "config_file:="], "'-p config_file:='", "write -p NAME:=VALUE with a value"),
        (["-p"], "-p flag. No parameter override rule found", "write -p NAME:=VALUE with a value"),
        (
            ["--params-file", "/nonexistent.yaml"],
            "'--params-file /nonexistent.yaml'. Error: Error opening YAML file",
            "give --params-file the path of a readable parameters YAML file",
        ),
        (["-r", "foo"], "'-r foo'", "write -r FROM:=TO"),
        (
            ["-r", "__node:=my-bridge"],
            "'-r __node:=my-bridge'",
            "write -r FROM:=TO, e.g. -r __ns:=/robot1; a ROS name is letters, digits and "
            "underscores between its '/' (no '-', '.' or spaces), and a node name starts with a "
            "letter",
        ),
        (
            ["--log-level", "loud"],
            "'--log-level loud'. Error: Argument does not use a valid severity level",
            "write --log-level LEVEL: debug, info, warn, error or fatal",
        ),
        (
            ["--enclave"],
            "--enclave flag. No enclave path provided",
            "see 'Passing ROS arguments to nodes'",
        ),
    ],
)
def test_a_bad_ros_argument_is_named_with_its_fix(
    ros_args: list[str], named: str, fix: str
) -> None:
    problem = ros_arguments_problem("parameter_bridge", ["pb", "--ros-args", *ros_args])
    assert problem.startswith("parameter_bridge: bad ROS argument: Couldn't parse ")
    assert f"{named}; {fix}" in problem
    assert ", at /" not in problem  # rcl's source locations
    assert "lexeme" not in problem  # rcl's lexer state


def test_arguments_inside_the_ros_arguments_are_named() -> None:
    problem = ros_arguments_problem("image_bridge", ["ib", "--ros-args", "-p", "a:=1", "/c", "d"])
    assert problem == (
        "image_bridge: not ROS arguments, yet after --ros-args: '/c', 'd'; "
        + MISPLACED.format(program="image_bridge")
        + " arguments"
    )


@pytest.mark.parametrize(
    "argv",
    [
        ["pb"],
        ["pb", TOPIC],
        ["pb", "--ros-args", "-p", "lazy:=true", "--", TOPIC],
        ["pb", TOPIC, "--ros-args", "-p", "config_file:=b.yaml", "-r", "__ns:=/r1"],
    ],
)
def test_readable_ros_arguments_have_no_problem(argv: list[str]) -> None:
    assert ros_arguments_problem("parameter_bridge", argv) == ""


@pytest.mark.parametrize("program", list(TOPICS))
@pytest.mark.parametrize(
    ("ros_args", "wanted"),
    [
        (["-p", "config_file"], "bad ROS argument: Couldn't parse parameter override rule"),
        (["--params-file", "/nonexistent.yaml"], "bad ROS argument: Couldn't parse params file"),
    ],
)
def test_each_executable_says_one_line_for_a_bad_ros_argument(
    program: str, ros_args: list[str], wanted: str
) -> None:
    status, lines = run(program, TOPICS[program], "--ros-args", *ros_args)
    assert status == USAGE_EXIT
    assert len(lines) == 1, lines
    assert lines[0].startswith(f"{program}: {wanted}")


@pytest.mark.parametrize("program", list(TOPICS))
def test_each_executable_names_a_topic_after_the_ros_arguments(program: str) -> None:
    status, lines = run(program, "--ros-args", "-p", "lazy:=true", TOPICS[program])
    assert status == USAGE_EXIT
    assert lines == [
        f"{program}: not ROS arguments, yet after --ros-args: '{TOPICS[program]}'; "
        + MISPLACED.format(program=program)
        + " arguments"
    ]


@pytest.mark.ros
@pytest.mark.parametrize("program", ["parameter_bridge", "image_bridge"])
@pytest.mark.parametrize(
    ("ros_args", "env", "wanted"),
    [
        (
            ["-p", "gz_transport_implementation:=foo"],
            {},
            "parameter gz_transport_implementation is 'foo', not a Gazebo Transport "
            "implementation; use one of zenoh, zeromq",
        ),
        (
            [],
            {TRANSPORT_IMPLEMENTATION_ENV: "foo"},
            f"{TRANSPORT_IMPLEMENTATION_ENV} is 'foo', not a Gazebo Transport implementation",
        ),
        (
            ["-p", "subscription_heartbeat:=0"],
            {},
            "parameter subscription_heartbeat is 0; it must be an integer >= 1",
        ),
    ],
)
def test_a_refused_parameter_is_one_error_line(
    program: str, ros_args: list[str], env: dict[str, str], wanted: str
) -> None:
    status, lines = run(program, TOPICS[program], "--ros-args", *ros_args, env=env)
    assert status == USAGE_EXIT
    assert len(lines) == 1, lines
    assert "[ERROR]" in lines[0]
    assert wanted in lines[0]


@pytest.mark.ros
@pytest.mark.parametrize("program", ["parameter_bridge", "image_bridge"])
def test_a_zenoh_router_not_there_is_one_error_line(program: str) -> None:
    """Zenoh in client mode towards a port nobody listens on (loopback, no scouting): the
    session cannot open; said once with where it looked and the fix, exit 1."""
    env = {
        TRANSPORT_IMPLEMENTATION_ENV: "zenoh",
        "GZ_TRANSPORT_ZENOH_CONFIG_OVERRIDE": (
            'mode="client";connect/endpoints=["tcp/127.0.0.1:1"];scouting/multicast/enabled=false'
        ),
    }
    status, lines = run(program, TOPICS[program], env=env)
    assert status == 1
    assert len(lines) == 1, lines
    assert "[ERROR]" in lines[0]
    assert 'cannot open the Zenoh session (Zenoh client, connect ["tcp/127.0.0.1:1"]' in lines[0]
    assert lines[0].endswith(
        "start the router it connects to, or set its endpoints (ZENOH_CONFIG, "
        "GZ_TRANSPORT_ZENOH_CONFIG_OVERRIDE; docs/zenoh.md)"
    )


@pytest.mark.parametrize(
    "argv",
    [
        ["parameter_bridge", "--help"],
        ["image_bridge", "--help"],
        ["bridge_types", "--print-pairs"],
        ["bridge_types", "--json"],
    ],
)
def test_a_reader_that_closed_the_pipe_gets_no_traceback(argv: list[str]) -> None:
    """``parameter_bridge --help | head -1``: the reader goes before the output is written."""
    program, *args = argv
    with subprocess.Popen(
        [str(BIN / program), *args], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True
    ) as process:
        assert process.stdout is not None
        process.stdout.close()
        _, stderr = process.communicate(timeout=30)
    assert "Traceback" not in stderr
    assert "BrokenPipeError" not in stderr
    assert process.returncode == 1


@pytest.mark.ros
@pytest.mark.parametrize("program", ["parameter_bridge", "image_bridge"])
def test_ctrl_c_ends_the_wait_for_a_zenoh_router(program: str) -> None:
    """A Zenoh client told to wait for its router for ever (docs/zenoh.md: connect/timeout_ms)
    blocked in Zenoh's native code: SIGINT and SIGTERM did nothing until a router came."""
    env = {
        **os.environ,
        TRANSPORT_IMPLEMENTATION_ENV: "zenoh",
        "GZ_TRANSPORT_ZENOH_CONFIG_OVERRIDE": (
            'mode="client";connect/endpoints=["tcp/127.0.0.1:1"];connect/timeout_ms=-1;'
            "scouting/multicast/enabled=false"
        ),
    }
    with subprocess.Popen(
        [str(BIN / program), TOPICS[program]],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        text=True,
        env=env,
    ) as process:
        assert process.stderr is not None
        waiting = "node has not started after 2 s (a Zenoh client waits for its router)"
        lines = []
        watchdog = threading.Timer(60.0, process.kill)  # should the line never come
        watchdog.start()
        for line in process.stderr:  # the line comes after 2 s; the process waits for ever
            lines.append(line)
            if waiting in line:
                break
        process.send_signal(signal.SIGINT)
        _, rest = process.communicate(timeout=30)
        watchdog.cancel()
    assert any(waiting in line for line in lines), lines
    assert process.returncode == 0, rest
    assert "[ERROR]" not in rest
    assert "Traceback" not in rest

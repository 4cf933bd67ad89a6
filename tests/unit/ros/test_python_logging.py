"""The package's Python log records, written as the bridge node's lines (ros/python_logging.py)."""

from __future__ import annotations

import logging
import re
import uuid

import pytest
import rclpy.logging
from rclpy.logging import LoggingSeverity

from ros_gz_bridge_py.ros.python_logging import PACKAGE, python_logging_to


def line(severity: str, name: str, message: str) -> str:
    """rcutils's default line for ``message``, its time stamp left out."""
    return f"[{severity}] [TIME] [{name}]: {message}"


def test_records_take_the_node_loggers_name_format_and_level(
    capfd: pytest.CaptureFixture[str],
) -> None:
    """Before, a transport warning was a bare stderr line whatever --log-level said, and its
    debug lines never showed, even with --log-level debug."""
    name = f"python_logging_{uuid.uuid4().hex[:8]}"
    node_logger = rclpy.logging.get_logger(name)
    rclpy.logging.set_logger_level(name, LoggingSeverity.DEBUG)
    transport = logging.getLogger(f"{PACKAGE}.transport.settings")
    with python_logging_to(node_logger):
        transport.debug("heard %d peers", 3)
        transport.warning("ignoring %s", "GZ_X")
    transport.warning("after the block")  # no longer the node's
    err = re.sub(r"\] \[[0-9.]+\] \[", "] [TIME] [", capfd.readouterr().err)
    assert line("DEBUG", name, "heard 3 peers") in err.splitlines()
    assert line("WARN", name, "ignoring GZ_X") in err.splitlines()
    assert f"[{name}]: after the block" not in err
    assert logging.getLogger(PACKAGE).handlers == []


def test_a_quieter_node_logger_leaves_the_records_below_its_level_out(
    capfd: pytest.CaptureFixture[str],
) -> None:
    name = f"python_logging_{uuid.uuid4().hex[:8]}"
    node_logger = rclpy.logging.get_logger(name)
    rclpy.logging.set_logger_level(name, LoggingSeverity.ERROR)
    transport = logging.getLogger(f"{PACKAGE}.transport.zmq.node")
    with python_logging_to(node_logger):
        assert not transport.isEnabledFor(logging.WARNING)
        transport.warning("not shown")
        transport.error("shown")
    err = re.sub(r"\] \[[0-9.]+\] \[", "] [TIME] [", capfd.readouterr().err)
    assert f"[{name}]: not shown" not in err
    assert line("ERROR", name, "shown") in err.splitlines()

"""QuickLogger writes the record rclpy's logger writes, without rclpy's caller lookup.

Each case runs in a fresh Python process (rcutils' output format is read once, at rclpy.init)
whose stderr is the console output, formatted to show every field of the record.
"""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap

FORMAT = "{severity}|{name}|{function_name}|{file_name}|{line_number}|{message}"

SCRIPT = textwrap.dedent(
    """
    import rclpy
    from rclpy.logging import LoggingSeverity
    from ros_gz_bridge_py.ros.quick_log import quick_logger

    rclpy.init()
    node = rclpy.create_node("quick_log_test")
    logger = node.get_logger()
    quick = quick_logger(logger)

    def caller():
        logger.info("plain")  # line 12
        quick.info("quick")  # line 13
        quick.warning("warned")  # line 14
        quick.error("failed")  # line 15
        quick.debug("hidden")  # line 16: below the default threshold
        for _ in range(3):
            quick.info("once", once=True)  # rclpy's filters keep their state

    caller()
    assert quick_logger(quick) is quick
    logger.set_level(LoggingSeverity.DEBUG)
    quick.debug("shown")  # line 23
    node.destroy_node()
    rclpy.shutdown()
    """
)


def _records() -> list[list[str]]:
    env = os.environ | {"RCUTILS_CONSOLE_OUTPUT_FORMAT": FORMAT}  # conftest: loopback
    done = subprocess.run(
        [sys.executable, "-c", SCRIPT],
        check=False,
        env=env,
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert done.returncode == 0, done.stderr
    return [line.split("|") for line in done.stderr.splitlines() if line.count("|") == 5]


def test_the_record_is_the_one_rclpy_writes_with_the_callers_line() -> None:
    records = _records()
    by_message = {record[5]: record for record in records}
    plain, quick = by_message["plain"], by_message["quick"]
    # Same logger, function and file as rclpy's own record; the caller's own line.
    assert quick[:4] == plain[:4]
    assert quick[:3] == ["INFO", "quick_log_test", "caller"]
    assert quick[3].endswith("<string>")
    assert (plain[4], quick[4]) == ("12", "13")
    assert by_message["warned"][:1] + by_message["warned"][4:5] == ["WARN", "14"]
    assert by_message["failed"][:1] + by_message["failed"][4:5] == ["ERROR", "15"]


def test_severity_threshold_and_rclpy_filters_hold() -> None:
    messages = [record[5] for record in _records()]
    assert "hidden" not in messages
    assert messages.count("once") == 1
    assert "shown" in messages

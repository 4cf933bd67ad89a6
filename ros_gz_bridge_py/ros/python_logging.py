"""The package's Python ``logging`` records, written as the bridge node's log lines.

The transport and the native data plane log through Python's ``logging``: they know no ROS
node. With no handler, Python printed their warnings as bare lines on stderr (not on
``/rosout``, whatever ``--log-level`` said) and dropped their debug lines. The executables
route them to the node's logger for as long as they run: the same format as the node's own
lines, ``/rosout``, and the level rcutils gives that logger (``--ros-args --log-level debug``,
or ``--log-level ros_gz_bridge:=debug``). A program that embeds the bridge keeps its own
logging configuration: the library installs nothing.
"""

from __future__ import annotations

import contextlib
import logging
from collections.abc import Iterator
from typing import Any

from rclpy.logging import LoggingSeverity

from ros_gz_bridge_py.ros.quick_log import RCUTILS_WRITE

#: The logger every module of the package logs under.
PACKAGE = "ros_gz_bridge_py"

#: rcutils severities from the most severe; a record takes the first its level reaches.
_SEVERITIES = (
    LoggingSeverity.FATAL,
    LoggingSeverity.ERROR,
    LoggingSeverity.WARN,
    LoggingSeverity.INFO,
)


class NodeLogHandler(logging.Handler):
    """Writes each record through rcutils under the name of ``logger`` (an rclpy node's),
    with the record's own function, file and line."""

    def __init__(self, logger: Any) -> None:
        super().__init__()
        self._logger = logger
        self._name = str(logger.name)

    def emit(self, record: logging.LogRecord) -> None:
        try:
            message = self.format(record)
            severity = next(
                (level for level in _SEVERITIES if record.levelno >= level),
                LoggingSeverity.DEBUG,
            )
            if RCUTILS_WRITE is None:
                self._logger.log(message, severity)
            else:
                RCUTILS_WRITE(
                    severity, self._name, message, record.funcName, record.pathname, record.lineno
                )
        except Exception:  # logging must not raise into the code that logs
            self.handleError(record)


@contextlib.contextmanager
def python_logging_to(logger: Any) -> Iterator[NodeLogHandler]:
    """Route the package's records to ``logger`` (an rclpy node's) at its effective level,
    until the block ends."""
    package = logging.getLogger(PACKAGE)
    handler = NodeLogHandler(logger)
    level, propagate = package.level, package.propagate
    package.addHandler(handler)
    package.setLevel(int(logger.get_effective_level()) or logging.INFO)
    package.propagate = False
    try:
        yield handler
    finally:
        package.removeHandler(handler)
        package.setLevel(level)
        package.propagate = propagate

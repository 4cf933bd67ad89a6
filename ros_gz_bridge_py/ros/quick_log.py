"""rclpy's node logger without its cost per line.

For every line it writes, rclpy's ``RcutilsLogger.log`` finds the calling frame outside rclpy
with ``inspect.getframeinfo``, which reads the caller's source file to quote a line of it, and
``os.path.realpath``, which examines every component of the path. The bridge writes two
``Creating ...`` lines per entry before any message flows: with 66 entries and Gazebo traffic
already flowing, those lookups were about a fifth of the time from the first channel to the last
(issue 23). :class:`QuickLogger` hands rcutils the same record (logger name, severity, message,
function, file and line of the caller) from the frame alone, so the output, its format and
``/rosout`` are unchanged. Calls with rclpy's filter keywords (``once``, ``throttle_duration_sec``,
...) go to rclpy's own logger, which keeps their state.
"""

from __future__ import annotations

import os
import sys
from typing import Any

from rclpy.impl.implementation_singleton import rclpy_implementation as _rclpy
from rclpy.logging import LoggingSeverity

#: rclpy's binding that writes one record through rcutils (None where a build lacks it).
RCUTILS_WRITE = getattr(_rclpy, "rclpy_logging_rcutils_log", None)


class QuickLogger:
    """The methods of rclpy's logger the bridge calls, each writing through rcutils directly."""

    def __init__(self, logger: Any) -> None:
        self._logger = logger
        self._name = str(logger.name)

    @property
    def name(self) -> str:
        return self._name

    def debug(self, message: str, **filters: Any) -> None:
        self._log(LoggingSeverity.DEBUG, message, filters)

    def info(self, message: str, **filters: Any) -> None:
        self._log(LoggingSeverity.INFO, message, filters)

    def warning(self, message: str, **filters: Any) -> None:
        self._log(LoggingSeverity.WARN, message, filters)

    def error(self, message: str, **filters: Any) -> None:
        self._log(LoggingSeverity.ERROR, message, filters)

    def is_enabled_for(self, severity: LoggingSeverity) -> bool:
        return bool(self._logger.is_enabled_for(severity))

    def _log(self, severity: LoggingSeverity, message: str, filters: dict[str, Any]) -> None:
        if filters or RCUTILS_WRITE is None:
            self._logger.log(message, severity, **filters)
        elif self._logger.is_enabled_for(severity):
            caller = sys._getframe(2)  # _log <- info/warning/... <- the caller
            code = caller.f_code
            path = os.path.abspath(code.co_filename)  # as rclpy names it
            RCUTILS_WRITE(severity, self._name, message, code.co_name, path, caller.f_lineno)


def quick_logger(logger: Any) -> QuickLogger:
    """``logger`` (an rclpy node's) as a :class:`QuickLogger`, once."""
    return logger if isinstance(logger, QuickLogger) else QuickLogger(logger)

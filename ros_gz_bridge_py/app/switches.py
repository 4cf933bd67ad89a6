"""Environment switches that turn a default off (``ROS_GZ_BRIDGE_..._=off``): one rule for all."""

from __future__ import annotations

import os
from collections.abc import Mapping

#: Values (any case, surrounding spaces ignored) that turn a switch off.
OFF_VALUES = frozenset({"off", "0", "false", "no"})


def switched_off(name: str, env: Mapping[str, str] | None = None) -> bool:
    """True when the variable ``name`` of ``env`` (default: the process's) says off."""
    return (os.environ if env is None else env).get(name, "").strip().lower() in OFF_VALUES

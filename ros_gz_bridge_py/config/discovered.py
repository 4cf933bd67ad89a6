"""Which discovered Gazebo topics ``auto_bridge`` takes: the allow and deny patterns.

Each pattern is a Python regular expression searched in the Gazebo topic name (anchor it
with ``^`` and ``$`` to match the whole name). A topic is taken when some ``auto_bridge_allow``
pattern matches it (an empty list allows every topic) and no ``auto_bridge_deny`` pattern does.
"""

from __future__ import annotations

import re
from collections.abc import Sequence
from dataclasses import dataclass

from ros_gz_bridge_py.errors import ConfigError


@dataclass(frozen=True)
class AutoBridgeRules:
    """``auto_bridge`` and its patterns, compiled."""

    enabled: bool = False
    allow: tuple[re.Pattern[str], ...] = ()
    deny: tuple[re.Pattern[str], ...] = ()

    def admits(self, gz_topic: str) -> bool:
        """True when ``gz_topic`` is allowed and not denied."""
        allowed = not self.allow or any(p.search(gz_topic) for p in self.allow)
        return allowed and not any(p.search(gz_topic) for p in self.deny)

    def why_not(self, gz_topic: str) -> str:
        """Which parameter keeps ``gz_topic`` out ("" when it is admitted)."""
        for pattern in self.deny:
            if pattern.search(gz_topic):
                return f"auto_bridge_deny pattern '{pattern.pattern}' matches it"
        if self.allow and not any(p.search(gz_topic) for p in self.allow):
            return "no auto_bridge_allow pattern matches it"
        return ""


def compile_patterns(parameter: str, texts: Sequence[str]) -> tuple[re.Pattern[str], ...]:
    """The regular expressions of one parameter.

    Raises:
        ConfigError: one that does not compile, naming the parameter, its index and the fix.
    """
    compiled = []
    for index, text in enumerate(texts):
        try:
            compiled.append(re.compile(text))
        except re.error as err:
            msg = (
                f"{parameter}[{index}] '{text}' is not a regular expression: {err}; escape "
                r"special characters with \ (a literal dot is \.), '.*' matches any text"
            )
            raise ConfigError(msg, f"parameter {parameter}") from err
    return tuple(compiled)


def auto_bridge_rules(enabled: bool, allow: Sequence[str], deny: Sequence[str]) -> AutoBridgeRules:
    """The rules of the three parameters.

    Raises:
        ConfigError: a pattern that does not compile.
    """
    return AutoBridgeRules(
        enabled,
        compile_patterns("auto_bridge_allow", allow),
        compile_patterns("auto_bridge_deny", deny),
    )

"""The discovery engine's tables of remote endpoints, kept by topic and by (process, node)."""

from __future__ import annotations

from typing import TypeVar

_V = TypeVar("_V")


def drop_process(
    by_topic: dict[str, dict[tuple[str, str], _V]], process: str
) -> list[tuple[str, tuple[str, str]]]:
    """Remove the (process, node) entries of ``process``; the (topic, key) of each removed."""
    dropped = []
    for topic in list(by_topic):
        by_node = by_topic[topic]
        for key in [key for key in by_node if key[0] == process]:
            del by_node[key]
            dropped.append((topic, key))
        if not by_node:
            del by_topic[topic]
    return dropped

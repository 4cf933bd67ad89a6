"""What the bridges on one ROS node share: what they bridge, and the numbers of their helper
nodes.

A program may open two :class:`~ros_gz_bridge_py.core.bridge.Bridge` objects on one node (one
per Gazebo node: two simulators in one ROS process). One topic bridged by both would pass every
message twice, and their helper nodes of one name would be two ROS nodes of one name; so the
bridges of a node claim what they bridge here, and each takes a number for its helper nodes.
"""

from __future__ import annotations

import threading
import weakref
from collections.abc import Iterable
from typing import Any

from ros_gz_bridge_py.config import BridgeSpec
from ros_gz_bridge_py.core.spec_checks import Key, refuse_twice


class NodeShare:
    """The claims and helper numbers of the open bridges of one ROS node."""

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._claims: dict[Key, BridgeSpec] = {}
        self._numbers: set[int] = set()

    def number(self) -> int:
        """The smallest number no open bridge of the node holds (1 for the first)."""
        with self._lock:
            taken = next(n for n in range(1, len(self._numbers) + 2) if n not in self._numbers)
            self._numbers.add(taken)
            return taken

    def give_back(self, number: int) -> None:
        with self._lock:
            self._numbers.discard(number)

    def claim(self, spec: BridgeSpec, keys: Iterable[Key]) -> None:
        """Hold ``keys`` for ``spec``.

        Raises:
            ConfigError: one of them is held already (by this bridge or another of the node),
                naming the entry that holds it.
        """
        keys = list(keys)
        with self._lock:
            refuse_twice(spec, keys, self._claims)
            self._claims.update(dict.fromkeys(keys, spec))

    def release(self, spec: BridgeSpec) -> None:
        """Let go of what ``spec`` held (found by the spec: its names may no longer resolve,
        with rclpy shut down before the bridge closed)."""
        with self._lock:
            for key in [key for key, holder in self._claims.items() if holder is spec]:
                del self._claims[key]


_SHARES: weakref.WeakKeyDictionary[Any, NodeShare] = weakref.WeakKeyDictionary()
_SHARES_LOCK = threading.Lock()


def share_of(ros_node: Any) -> NodeShare:
    """The share of ``ros_node``'s bridges (made with the first)."""
    with _SHARES_LOCK:
        share = _SHARES.get(ros_node)
        if share is None:
            share = _SHARES[ros_node] = NodeShare()
        return share

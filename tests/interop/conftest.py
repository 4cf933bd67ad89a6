"""Fixtures for the interop tests against real Ignition Transport 11 processes.

Every test here gets its started processes stopped at the end (``gz_processes``), and may
ask for ``gz_node``: a started node of ours in the test session's partition.
"""

from __future__ import annotations

import sys
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

_ROOT = str(Path(__file__).resolve().parents[2])
if _ROOT not in sys.path:
    sys.path.insert(0, _ROOT)

from ros_gz_bridge_py.transport import create_gz_node  # noqa: E402
from testing.gzpeer import gz_processes, ign_peer, require_peer  # noqa: E402

__all__ = ["gz_node", "gz_processes", "ign_peer", "module_gz_node", "stop_started_processes"]


@pytest.fixture(autouse=True)
def stop_started_processes(gz_processes: None) -> None:
    """Apply the process clean-up to every test of this directory."""


@pytest.fixture
def gz_node() -> Iterator[Any]:
    """A started node of ours (closed after the test)."""
    with create_gz_node() as node:
        yield node


@pytest.fixture(scope="module")
def module_gz_node() -> Iterator[Any]:
    """One started node of ours for all the tests of a module (skips without the peer tools)."""
    require_peer()
    with create_gz_node() as node:
        yield node

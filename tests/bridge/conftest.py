"""Fixtures of the bridge tests that run the real ``parameter_bridge`` executable."""

from __future__ import annotations

from collections.abc import Iterator

import pytest

from testing.e2e_harness import ProcessGroup


@pytest.fixture(scope="module")
def module_processes() -> Iterator[ProcessGroup]:
    """Processes shared by the tests of one module, stopped after its last test."""
    group = ProcessGroup()
    yield group
    group.stop()

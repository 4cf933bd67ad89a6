"""Fixtures of the in-process core tests, and the two rules every one of them keeps.

* Loopback: ``tests/conftest.py`` puts the loopback environment (a domain and partition of
  this pytest process, localhost-only discovery) in ``os.environ`` when pytest starts. This
  file sets the host-only part again when imported (same values) and checks the whole
  before the first rclpy context of the package opens.
* One process: nothing in ``tests/core`` starts another process. Every way Python has to
  start one is refused while the package runs (``one_process.py``), and each test fails if
  it tried or left a child process.
"""

from __future__ import annotations

import os
import uuid
from collections.abc import Callable, Iterator
from typing import Any

import pytest

from tests.core.harness import TEST_OPTIONS, Rig, RosWorld
from tests.core.one_process import child_processes, refusing_processes

#: What tests/conftest.py sets (and ../shared/tools/loopback-env): traffic stays on this host.
LOOPBACK = {
    "ROS_AUTOMATIC_DISCOVERY_RANGE": "LOCALHOST",
    "ROS_LOCALHOST_ONLY": "1",
    "GZ_IP": "127.0.0.1",
    "IGN_IP": "127.0.0.1",
}
os.environ.update(LOOPBACK)


@pytest.fixture(scope="package", autouse=True)
def refused_processes() -> Iterator[list[str]]:
    """Refuse to start processes for the whole package; yields what was attempted."""
    unset = [name for name in ("ROS_DOMAIN_ID", "GZ_PARTITION") if not os.environ.get(name)]
    assert not unset, f"tests/conftest.py did not set {unset}: the loopback environment is missing"
    with refusing_processes() as attempts:
        yield attempts


@pytest.fixture(autouse=True)
def one_process(refused_processes: list[str]) -> Iterator[None]:
    """Fail the test that tried to start a process or left a child behind."""
    before = len(refused_processes)
    yield
    tried = refused_processes[before:]
    assert not tried, f"the test tried to start processes: {tried}"
    assert child_processes() == [], "the test left child processes"


@pytest.fixture(scope="module")
def world() -> Iterator[RosWorld]:
    """One rclpy context per test module, spun by one thread."""
    ros = RosWorld(f"core_test_{uuid.uuid4().hex[:8]}")
    yield ros
    ros.close()


@pytest.fixture
def make_rig(world: RosWorld) -> Iterator[Callable[..., Rig]]:
    """``make_rig(options=..., registry=..., node_options=...)``: bridges closed at test end."""
    rigs: list[Rig] = []

    def make(options: Any = TEST_OPTIONS, **kwargs: Any) -> Rig:
        rig = Rig(world, options, **kwargs)
        rigs.append(rig)
        return rig

    yield make
    for rig in reversed(rigs):
        rig.close()


@pytest.fixture
def rig(make_rig: Callable[..., Rig]) -> Rig:
    """A bridge with the test options (no lazy or explain timers at work)."""
    return make_rig()

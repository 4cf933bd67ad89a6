"""``parameter_bridge`` puts all its threads on one CPU while its load is light, and leaves
them on every CPU when switched off, when it carries images, or when it may use one CPU only
(app/one_cpu.py; when it spreads them again is tested on the policy alone, tests/unit/app)."""

from __future__ import annotations

import contextlib
import os

import pytest

from ros_gz_bridge_py.app.settings import ONE_CPU_ENV
from testing.behaviour_harness import STRING, WAIT, bridge_command, started
from testing.gzpeer import PeerProcess, start_process, unique_name, wait_for_line

__all__ = ["started"]

pytestmark = [
    pytest.mark.ros,
    pytest.mark.skipif(len(os.sched_getaffinity(0)) < 2, reason="one CPU: nothing to choose"),
]

PINNED = r"bridge threads on CPU (\d+): a light load"
#: Seconds past start-up a bridge that pins takes to do so: two looks, a second apart.
DECIDED = 4.0


def thread_cpus(pid: int) -> set[frozenset[int]]:
    """The CPU sets of ``pid``'s threads."""
    sets = set()
    for tid in os.listdir(f"/proc/{pid}/task"):
        with contextlib.suppress(OSError):  # ended meanwhile
            sets.add(frozenset(os.sched_getaffinity(int(tid))))
    return sets


def start(
    started: list[PeerProcess],
    args: list[str],
    env: dict[str, str] | None = None,
    prefix: tuple[str, ...] = (),
) -> PeerProcess:
    """A bridge, in ``started`` (stopped at test end, also when this wait fails) once its
    process exists, returned once it has created its channel."""
    bridge = start_process(
        [*prefix, *bridge_command(*args)], None if env is None else {**os.environ, **env}
    )
    started.append(bridge)
    wait_for_line(bridge, r"\]: Creating ", timeout=30)
    return bridge


def test_a_light_bridge_shares_one_cpu(started: list[PeerProcess]) -> None:
    bridge = start(started, [f"{unique_name('one_cpu')}@std_msgs/msg/String@{STRING}"])
    cpu = int(wait_for_line(bridge, PINNED, timeout=WAIT + DECIDED)[1])
    assert thread_cpus(bridge.pid) == {frozenset({cpu})}


@pytest.mark.parametrize(
    ("entry", "env", "prefix"),
    [
        (f"@std_msgs/msg/String@{STRING}", {ONE_CPU_ENV: "off"}, ()),
        ("@sensor_msgs/msg/Image[ignition.msgs.Image", None, ()),
        (f"@std_msgs/msg/String@{STRING}", None, ("taskset", "-c", "0")),
    ],
    ids=["switched-off", "images", "one-cpu-allowed"],
)
def test_threads_stay_where_they_were(
    started: list[PeerProcess], entry: str, env: dict[str, str] | None, prefix: tuple[str, ...]
) -> None:
    """Judged once a light bridge started after it has pinned: by then this one has looked at
    its load as often, and moved nothing."""
    allowed = frozenset({0}) if prefix else frozenset(os.sched_getaffinity(0))
    bridge = start(started, [unique_name("one_cpu") + entry], env, prefix)
    later = start(started, [f"{unique_name('one_cpu')}@std_msgs/msg/String@{STRING}"])
    wait_for_line(later, PINNED, timeout=WAIT + DECIDED)
    assert bridge.poll() is None
    assert thread_cpus(bridge.pid) == {allowed}
    assert "bridge threads on CPU" not in bridge.output()

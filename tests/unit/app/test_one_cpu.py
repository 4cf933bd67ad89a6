"""The one-CPU policy alone: when it pins the bridge's threads, where, and when it spreads them
again (the process's side is tested on a real ``parameter_bridge`` in tests/bridge)."""

from __future__ import annotations

from ros_gz_bridge_py.app.one_cpu import (
    FIRST_HOLD,
    LONGEST_HOLD,
    Move,
    OneCpuPolicy,
    Sample,
    cpu_ticks,
)

STAT = """cpu  100 0 50 800 10 0 5 0 0 0
cpu0 60 0 30 400 4 0 2 0 7 0
cpu1 40 0 20 400 6 0 3 1 0 5
cpu3 1 0 1 1 1 0 0 0 0 0
intr 12345
ctxt 678
"""


def test_cpu_ticks_are_busy_and_total_of_the_wanted_cpus_without_guest_time() -> None:
    assert cpu_ticks(STAT, {0, 1, 2}) == {0: (92, 496), 1: (64, 470)}


def is_pin(move: Move | None) -> bool:
    return move is not None and move.cpu is not None


class Feed:
    """Samples one second apart: each call gives the load (cores) and every CPU's busy share
    over the second before it."""

    def __init__(self) -> None:
        self.policy = OneCpuPolicy()
        self.time = 0.0
        self.cpu = 0.0
        self.ticks = {0: (0, 0), 1: (0, 0)}
        self.policy.step(self._sample(False))

    def _sample(self, bulk: bool) -> Sample:
        return Sample(time=self.time, cpu=self.cpu, cpu_ticks=dict(self.ticks), bulk=bulk)

    def second(
        self, load: float, shares: tuple[float, float] = (0.5, 0.5), bulk: bool = False
    ) -> Move | None:
        self.time += 1.0
        self.cpu += load
        self.ticks = {
            cpu: (busy + round(100 * share), total + 100)
            for (cpu, (busy, total)), share in zip(self.ticks.items(), shares, strict=True)
        }
        return self.policy.step(self._sample(bulk))

    def wait(self, seconds: float) -> None:
        """``seconds`` without a sample (the hold passes)."""
        self.time += seconds - 1.0
        assert self.second(0.1) is None


def test_a_light_load_goes_to_the_least_busy_cpu() -> None:
    feed = Feed()
    move = feed.second(0.2, shares=(0.9, 0.3))
    assert move == Move(1, "a light load (the bridge used 20% of a core)")
    assert feed.policy.pinned == 1
    assert feed.second(0.2, shares=(0.2, 0.9)) is None  # stays where it is
    assert feed.policy.pinned == 1


def test_equal_cpus_take_the_lowest_number() -> None:
    assert Feed().second(0.1) == Move(0, "a light load (the bridge used 10% of a core)")


def test_a_heavy_load_is_not_pinned() -> None:
    feed = Feed()
    assert feed.second(0.51) is None
    assert feed.policy.pinned is None
    assert feed.second(0.5) == Move(0, "a light load (the bridge used 50% of a core)")


def test_a_bulk_channel_is_not_pinned() -> None:
    feed = Feed()
    assert feed.second(0.01, bulk=True) is None
    assert feed.policy.pinned is None


def test_a_bulk_channel_releases_and_holds() -> None:
    feed = Feed()
    assert is_pin(feed.second(0.1))
    move = feed.second(0.1, bulk=True)
    assert move == Move(
        None,
        "an image or point cloud channel (the bridge used 10% of a core); "
        f"spread for {FIRST_HOLD:.0f} s",
    )
    assert feed.policy.pinned is None


def test_a_heavy_load_releases() -> None:
    feed = Feed()
    assert is_pin(feed.second(0.3))
    assert feed.second(0.7) is None
    move = feed.second(0.71)
    assert move is not None
    assert move.cpu is None  # a release
    assert move.why.startswith("a heavy load (the bridge used 71% of a core)")


def test_a_full_cpu_releases_only_while_another_has_room() -> None:
    feed = Feed()
    assert feed.second(0.2, shares=(0.5, 0.4)) == Move(
        1, "a light load (the bridge used 20% of a core)"
    )
    assert feed.second(0.2, shares=(0.94, 1.0)) is None  # nowhere better to go
    assert feed.second(0.2, shares=(0.76, 1.0)) is None
    move = feed.second(0.2, shares=(0.75, 0.95))
    assert move is not None
    assert move.cpu is None  # a release
    # it read "CPU 1 full while another has room (20% of a core)": the bridge's own share
    assert move.why.startswith(
        "CPU 1 95% busy, mostly with other work, another 75% (the bridge used 20% of a core)"
    )


def test_the_hold_doubles_at_each_release_up_to_its_longest() -> None:
    feed = Feed()
    hold = FIRST_HOLD
    for _ in range(8):
        assert is_pin(feed.second(0.1))
        move = feed.second(0.9)
        assert move is not None
        assert move.cpu is None  # a release
        assert move.why.endswith(f"spread for {hold:.0f} s")
        feed.wait(hold - 1.0)  # not yet
        assert feed.policy.pinned is None
        feed.time += 1.0
        hold = min(hold * 2, LONGEST_HOLD)
    assert hold == LONGEST_HOLD


def test_a_clock_that_did_not_move_decides_nothing() -> None:
    feed = Feed()
    feed.time -= 1.0
    assert feed.second(0.1) is None
    assert feed.second(0.1) == Move(0, "a light load (the bridge used 10% of a core)")


def test_a_single_cpu_is_never_pinned() -> None:
    policy = OneCpuPolicy()
    for second in range(3):
        sample = Sample(
            time=float(second), cpu=0.1 * second, cpu_ticks={0: (second, 10 * second)}, bulk=False
        )
        assert policy.step(sample) is None

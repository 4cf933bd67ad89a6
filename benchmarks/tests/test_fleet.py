"""The fleet benchmark's report logic: the subscriber layout, the order of the rounds, a fleet
size summed up from its rounds against the same run's ceiling, and the goals judged on them."""

from __future__ import annotations

from benchmarks import fleet, fleet_goals
from benchmarks.fleet_goals import KINDS, Round, Size, goal_lines, span
from benchmarks.fleet_ros import parts
from benchmarks.fleet_rounds import schedule


def row(robots: int, us: float, *, ceiling: bool = False, order: int = 0, **shares: float) -> Round:
    """A round of one second with 10,000 messages: its CPU percentage is its µs per message."""
    delivered = {kind: shares.get(kind, 1.0) for kind in KINDS}
    return Round(
        robots, ceiling, 1.0, us, delivered, 10_000, threads=20, rss=150.0, rss_peak=170.0,
        order=order,
    )  # fmt: skip


def test_clock_has_a_process_of_its_own_and_robots_go_ten_to_a_process() -> None:
    assert parts(10) == [["--clock"], ["--robots", "1", "10"]]
    assert parts(25) == [
        ["--clock"],
        ["--robots", "1", "10"],
        ["--robots", "11", "20"],
        ["--robots", "21", "25"],
    ]
    assert len(parts(50)) == 6


def test_the_rounds_alternate_which_side_goes_first() -> None:
    assert schedule([10, 25], 2) == [
        (10, False), (10, True), (10, True), (10, False),
        (25, False), (25, True), (25, True), (25, False),
    ]  # fmt: skip
    assert schedule([50], 1) == [(50, False), (50, True)]


def test_a_size_is_the_median_of_its_rounds_and_each_pair_gives_a_ratio() -> None:
    rows = [
        row(10, 50.0), row(10, 40.0, ceiling=True), row(10, 36.0, ceiling=True),
        row(10, 46.0), row(10, 44.0), row(10, 38.0, ceiling=True),
        Round(10, False, error="bridge did not start"),  # left out, not a zero
    ]  # fmt: skip
    size = Size.of(10, rows)
    assert (size.us, size.ceiling_us) == (46.0, 38.0)
    assert round(size.ratio, 3) == round(46 / 38, 3)
    assert [round(r, 3) for r in size.pair_ratios()] == [1.25, round(46 / 36, 3), round(44 / 38, 3)]
    assert span([r.us_per_message for r in size.bridge]) == "46.0 (44.0-50.0)"
    assert span([20, 20], 0) == "20"


def test_the_goals_compare_the_bridge_with_the_ceiling_of_the_same_run() -> None:
    rows = [
        row(10, 44.0), row(10, 40.0, ceiling=True),  # 1.10x: met
        row(25, 30.0, imu=0.97), row(25, 20.0, ceiling=True, imu=0.99),  # 1.5x; imu below
        row(50, 20.0, clock=0.9), row(50, 20.0, ceiling=True, clock=0.5),  # /clock 90%
    ]  # fmt: skip
    verdicts = {
        line.split(":")[0].split(" (")[0]: line.rsplit("— ", 1)[1] for line in goal_lines(rows)
    }
    assert verdicts == {
        "- CPU per delivered message at 10 robots <= 1.1x the same run's rclpy ceiling": "**met**",
        "- CPU per delivered message at 25 robots <= 1.1x the same run's rclpy ceiling": (
            "**missed**"
        ),
        "- CPU per delivered message at 50 robots <= 1.1x the same run's rclpy ceiling": "**met**",
        "- delivered at 25 robots": "**missed**",
        "- /clock >= 95% at 50 robots, whatever else is lost": "**missed**",
        "- flat": "**missed**",  # 20 µs is 55% below 44
        "- threads <= 20 for any fleet": "**met**",
    }
    delivered = next(line for line in goal_lines(rows) if "delivered at 25" in line)
    assert delivered.endswith("short: imu — **missed**")


def test_delivery_below_the_ceilings_own_misses_even_above_the_floor() -> None:
    ceiling = dict.fromkeys(KINDS, 1.0)
    assert fleet_goals.short_kinds({**ceiling, "odom": 0.99}, ceiling) == ["odom"]
    assert fleet_goals.short_kinds({**ceiling, "odom": 0.996}, ceiling) == []  # window noise
    assert fleet_goals.short_kinds({**ceiling, "clock": 0.94}, {**ceiling, "clock": 0.9}) == [
        "clock"
    ]


def test_the_stored_figures_are_the_medians_and_the_ratios_range() -> None:
    rows = [row(10, 50.0), row(10, 40.0, ceiling=True), row(10, 42.0, ceiling=True), row(10, 46.0)]
    stored = fleet.numbers(rows)
    assert stored["fleet10.us_per_message"] == 48.0
    assert stored["ceiling10.us_per_message"] == 41.0
    assert stored["fleet10.ratio"] == round(48 / 41, 3)
    assert (stored["fleet10.ratio_min"], stored["fleet10.ratio_max"]) == (1.095, 1.25)
    assert stored["fleet10.rss_peak_mb"] == 170.0
    assert stored["ceiling10.delivered.cmd_vel"] == 1.0

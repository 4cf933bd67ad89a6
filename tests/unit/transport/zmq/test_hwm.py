"""The one policy turning a byte budget into a ZeroMQ high-water mark (zmq/hwm.py)."""

from __future__ import annotations

import pytest

from ros_gz_bridge_py.transport.zmq.hwm import MAX_HWM, MIN_HWM, hwm_for_bytes

MIB = 1024 * 1024


@pytest.mark.parametrize(
    ("largest", "budget", "configured", "expected"),
    [
        (0, 64 * MIB, 1000, 1000),  # nothing sent yet: the configured count
        (100, 64 * MIB, 1000, 1000),  # small messages: the count binds first
        (6 * MIB, 64 * MIB, 1000, 10),  # 6 MB images: 10 fit in 64 MiB
        (64 * MIB, 64 * MIB, 1000, MIN_HWM),  # one message fills the budget: the floor
        (200 * MIB, 64 * MIB, 1000, MIN_HWM),  # larger than the budget: still the floor
        (6 * MIB, 64 * MIB, 5, 5),  # a configured count below the byte bound
        (6 * MIB, 64 * MIB, 1, 1),  # the floor never raises a configured count
        (6 * MIB, 64 * MIB, 0, 10),  # 0 (no count limit): the bytes alone
        (0, 64 * MIB, 0, 0),  # 0 and nothing sent: still no count limit
        (1, 2**40, 0, MAX_HWM),  # no count limit, tiny messages: libzmq's largest mark
    ],
)
def test_hwm_for_bytes(largest: int, budget: int, configured: int, expected: int) -> None:
    assert hwm_for_bytes(largest, budget, configured) == expected


def test_the_queue_it_allows_stays_within_the_budget_above_the_floor() -> None:
    for largest in (1, 1000, 65_536, 1_000_003, 6 * MIB, 32 * MIB):
        hwm = hwm_for_bytes(largest, 64 * MIB, 1000)
        assert hwm * largest <= 64 * MIB or hwm == MIN_HWM

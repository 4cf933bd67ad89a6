"""``BridgeOptions`` refuses numbers the bridge cannot run with, before anything is opened."""

from __future__ import annotations

import pytest

from ros_gz_bridge_py.core.options import BridgeOptions
from ros_gz_bridge_py.errors import ConfigError


@pytest.mark.parametrize(
    ("field", "value", "takes"),
    [("heartbeat", 0.0, "seconds between lazy re-checks, > 0 (1.0)"),
     ("heartbeat", -1.0, "seconds between lazy re-checks, > 0 (1.0)"),
     ("heartbeat", float("nan"), "seconds between lazy re-checks, > 0 (1.0)"),
     ("service_timeout", 0.0, "seconds, > 0"),
     ("max_rate", -1.0, "messages per second, 0 for no limit"),
     ("max_rate", float("inf"), "messages per second, 0 for no limit"),
     ("max_queued_bytes", 0, "bytes, at least 1")],
)  # fmt: skip
def test_a_number_the_bridge_cannot_run_with_is_named_with_what_it_takes(
    field: str, value: float, takes: str
) -> None:
    """A heartbeat of 0 was a timer spinning a core; a negative one rcl's raw error."""
    with pytest.raises(ConfigError) as raised:
        BridgeOptions(**{field: value})  # type: ignore[arg-type]
    assert str(raised.value) == f"BridgeOptions({field}={value!r}): give {takes}"


def test_the_defaults_and_the_bounds_are_taken() -> None:
    assert BridgeOptions().heartbeat == 1.0
    taken = BridgeOptions(heartbeat=0.001, service_timeout=0.1, max_rate=0.0, max_queued_bytes=1)
    assert (taken.heartbeat, taken.max_rate, taken.max_queued_bytes) == (0.001, 0.0, 1)

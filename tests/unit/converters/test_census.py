"""Lists counted before the parse (converters/census.py): a message whose list is too large
for certain is refused without parsing its items, only where the full parse refuses it too,
and a message within the bound is never refused."""

from __future__ import annotations

import math
from typing import Any

import pytest

from ros_gz_bridge_py.converters._limits import OUTPUT_FLOOR, OUTPUT_RATIO
from ros_gz_bridge_py.converters.census import ListCensus, census_for
from ros_gz_bridge_py.converters.registry import default_registry
from ros_gz_bridge_py.errors import ConversionError
from ros_gz_bridge_py.msgs import message_class
from tests.unit.native import gz_payloads as gzp
from tools.native_fuzz_programs import distinctive

CENSUSES = [
    (pair, census)
    for pair in default_registry().pairs
    if (census := census_for(pair.to_ros, pair.gz_type)) is not None
]
IDS = [f"{pair.ros_type}-{pair.gz_type}" for pair, _census in CENSUSES]


def test_the_amplifying_lists_have_a_census() -> None:
    """Those of the issue: a Pose_V of empty poses as a TFMessage or a PoseArray."""
    counted = {
        (pair.ros_type, entry.name, entry.number) for pair, c in CENSUSES for entry in c.lists
    }
    assert ("tf2_msgs/msg/TFMessage", "pose", 2) in counted
    assert ("geometry_msgs/msg/PoseArray", "pose", 2) in counted


@pytest.mark.parametrize(("pair", "census"), CENSUSES, ids=IDS)
def test_empty_elements_past_the_bound_are_refused_before_the_parse(
    pair: Any, census: ListCensus
) -> None:
    """For each list whose items can pass the bound at a modest count: enough empty elements
    that the census refuses them, and the full parse and conversion refuse them too."""
    checked = 0
    for entry in census.lists:
        element = gzp.length_delimited(entry.number, b"")
        room = entry.least - 2 * OUTPUT_RATIO * len(element)
        if room <= 0:
            continue  # only the 128 MiB cap can refuse these: millions of elements
        count = 2 * math.ceil(OUTPUT_FLOOR / room) + 1
        payload = element * count
        with pytest.raises(ConversionError, match=rf"a list of {count} \w+ items .* over the"):
            census.check(payload)
        gz = message_class(pair.gz_type).FromString(payload)
        with pytest.raises(ConversionError, match=r"over the limit"):
            pair.to_ros(gz)
        checked += 1
    if not checked:
        pytest.skip("no list of this pair passes the bound below the cap")


@pytest.mark.parametrize(("pair", "census"), CENSUSES, ids=IDS)
def test_a_large_message_within_the_bound_passes(pair: Any, census: ListCensus) -> None:
    """Each list given thousands of whole elements: over the size where the census is taken,
    and converted by the Python path; the census must not refuse it."""
    message = distinctive(pair.gz_type)
    for entry in census.lists:
        items = getattr(message, entry.name)
        element = items[0]
        count = 2 * census.needed_above // max(element.ByteSize(), 1) + 1
        for _ in range(min(count, 20_000)):
            items.add().CopyFrom(element)
    payload = message.SerializeToString()
    census.check(payload)
    pair.to_ros(message_class(pair.gz_type).FromString(payload))

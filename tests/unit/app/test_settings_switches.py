"""The one rule that turns an environment switch off."""

from __future__ import annotations

import pytest

from ros_gz_bridge_py.app.settings import read_switches, switched_off

NAME = "ROS_GZ_BRIDGE_SOMETHING"


@pytest.mark.parametrize("value", ["off", "OFF", " off ", "0", "false", "False", "no"])
def test_off_values(value: str) -> None:
    assert switched_off(NAME, {NAME: value})


@pytest.mark.parametrize("value", ["", "on", "1", "true", "yes", "offf", "single"])
def test_anything_else_leaves_the_default_on(value: str) -> None:
    assert not switched_off(NAME, {NAME: value})


def test_unset_is_on() -> None:
    assert not switched_off(NAME, {})


@pytest.mark.parametrize(("value", "nice"), [("", 10), ("0", 0), (" 5 ", 5), ("-3", -3)])
def test_bulk_nice_values(value: str, nice: int) -> None:
    switches = read_switches({"ROS_GZ_BRIDGE_BULK_NICE": value})
    assert switches.bulk_nice == nice
    assert switches.warnings == ()


def test_bulk_nice_that_is_not_a_number_is_reported() -> None:
    switches = read_switches({"ROS_GZ_BRIDGE_BULK_NICE": "low"})
    assert switches.bulk_nice == 10
    assert switches.warnings == (
        "ROS_GZ_BRIDGE_BULK_NICE='low' is not an integer; using 10 "
        "(set a whole number, 0 to keep image threads at normal priority)",
    )

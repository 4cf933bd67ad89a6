"""LateResponses' bookkeeping with a scripted sender: what is held, sent again, given up, and
who is told. The real rmw timeout is in tests/core/test_services.py."""

from __future__ import annotations

from collections.abc import Iterator
from typing import Any

import pytest
import rclpy
from rclpy.context import Context

from ros_gz_bridge_py.ros.late_responses import LateResponses


class Owner:
    def __init__(self) -> None:
        self.late: list[float] = []
        self.lost: list[tuple[float, str]] = []

    def answered_late(self, waited: float) -> None:
        self.late.append(waited)

    def not_answered(self, waited: float, why: str) -> None:
        self.lost.append((waited, why))


class Service:
    """Stands for an rclpy service: LateResponses sets its send_response."""

    send_response: Any = None


class Script:
    """A sender that fails for the responses named in ``failing`` and records each try."""

    def __init__(self) -> None:
        self.failing: set[str] = set()
        self.tries: list[str] = []

    def __call__(self, _service: Any, response: str, _header: Any) -> bool:
        self.tries.append(response)
        return response not in self.failing


class Clock:
    def __init__(self) -> None:
        self.now = 100.0

    def __call__(self) -> float:
        return self.now


@pytest.fixture
def node() -> Iterator[Any]:
    context = Context()
    rclpy.init(context=context)
    made = rclpy.create_node("late_responses_test", context=context)
    yield made
    made.destroy_node()
    rclpy.shutdown(context=context)


def make(node: Any, **kwargs: Any) -> tuple[LateResponses, Script, Clock, Service, Owner]:
    script, clock, service, owner = Script(), Clock(), Service(), Owner()
    late = LateResponses(node, send=script, clock=clock, **kwargs)
    late.serve(service, owner)
    return late, script, clock, service, owner


def test_a_response_that_goes_out_is_not_held(node: Any) -> None:
    late, script, _, service, owner = make(node)
    service.send_response("a", "header")
    assert (script.tries, late.held, owner.late, owner.lost) == (["a"], 0, [], [])


def test_a_held_response_goes_out_once_its_client_is_found(node: Any) -> None:
    late, script, clock, service, owner = make(node, patience=5.0)
    script.failing = {"a"}
    service.send_response("a", "header")
    assert late.held == 1
    clock.now += 1.0
    late.retry()
    assert (late.held, owner.late) == (1, [])
    script.failing.clear()
    clock.now += 0.5
    late.retry()
    assert (late.held, owner.late, owner.lost) == (0, [1.5], [])
    assert script.tries == ["a", "a", "a"]


def test_a_held_response_is_given_up_after_its_patience(node: Any) -> None:
    late, script, clock, service, owner = make(node, patience=2.0)
    script.failing = {"a", "b"}
    service.send_response("a", "header")
    clock.now += 1.0
    service.send_response("b", "header")
    clock.now += 1.0
    late.retry()
    assert [waited for waited, _ in owner.lost] == [2.0]
    assert "never discovered" in owner.lost[0][1]
    assert late.held == 1  # b waited 1 s of its 2


def test_past_the_limit_the_oldest_is_given_up_and_order_is_kept(node: Any) -> None:
    late, script, clock, service, owner = make(node, limit=2)
    script.failing = {"a", "b", "c"}
    for response in ("a", "b", "c"):
        service.send_response(response, "header")
        clock.now += 1.0
    assert late.held == 2
    assert owner.lost == [(2.0, "2 responses already waited for their clients to be discovered")]
    script.tries.clear()
    late.retry()
    assert script.tries == ["b", "c"]

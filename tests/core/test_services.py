"""Service forwarding in one process: ROS clients calling memory Gazebo providers.

The bridge serves each ROS service on its side node (spun by the side node's own executor)
and forwards each request to the Gazebo provider; the providers here are memory nodes whose
handlers record what they got, so converted requests are checked where Gazebo sees them.
"""

from __future__ import annotations

import threading
import time
import uuid
from collections.abc import Callable
from typing import Any

import pytest
import rclpy
from rclpy.context import Context
from rclpy.qos import DurabilityPolicy, QoSProfile
from rclpy.utilities import try_shutdown
from ros_gz_interfaces.srv import ControlWorld, DeleteEntity, SetEntityPose

from ros_gz_bridge_py.config import ServiceBridgeSpec
from ros_gz_bridge_py.core.services import HeldBytes
from ros_gz_bridge_py.core.status import StatusTracker
from ros_gz_bridge_py.msgs import message_class
from ros_gz_bridge_py.msgs.names import Spelling, respell
from tests.core.harness import WAIT, Rig, RosWorld, options, unique, wait_until

pytestmark = [pytest.mark.ros]  # rclpy participants, in this process

SERVICE_TIMEOUT = 0.3
CONTROL_WORLD = "ros_gz_interfaces/srv/ControlWorld"
GzWorldControl = message_class("gz.msgs.WorldControl")
GzBoolean = message_class("gz.msgs.Boolean")
GzPose = message_class("gz.msgs.Pose")


@pytest.fixture
def rig(make_rig: Callable[..., Rig]) -> Rig:
    """A bridge whose service calls give up after :data:`SERVICE_TIMEOUT` seconds."""
    return make_rig(options(service_timeout=SERVICE_TIMEOUT))


class Provider:
    """A Gazebo service handler that decodes and keeps every request, and replies ``reply``
    (``None``: Gazebo reports failure; an exception: the handler raises)."""

    def __init__(self, request_class: Any, reply: Any) -> None:
        self.request_class = request_class
        self.reply = reply
        self.requests: list[Any] = []

    def __call__(self, payload: bytes) -> tuple[bool, bytes]:
        self.requests.append(self.request_class.FromString(payload))
        if isinstance(self.reply, Exception):
            raise self.reply
        if self.reply is None:
            return False, b""
        return True, self.reply.SerializeToString()


def call(world: RosWorld, srv_type: Any, service: str, request: Any) -> Any:
    """One call through a client of the test node; fails the test without a response."""
    client = world.run(lambda: world.node.create_client(srv_type, service))
    try:
        wait_until(client.service_is_ready, f"the service {service}")
        future = world.run(lambda: client.call_async(request))
        wait_until(future.done, f"a response from {service}", timeout=WAIT + SERVICE_TIMEOUT)
        return future.result()
    finally:
        world.destroy(client)


def control_request() -> Any:
    request = ControlWorld.Request()
    request.world_control.pause = True
    request.world_control.multi_step = 7
    request.world_control.reset.model_only = True
    return request


@pytest.mark.parametrize("native", [Spelling.GZ, Spelling.IGNITION])
def test_a_call_reaches_gazebo_and_the_reply_comes_back(
    rig: Rig, world: RosWorld, native: Spelling
) -> None:
    """The default (gz.msgs) types reach a provider of either Gazebo line."""
    service = unique("control")
    rig.add(ServiceBridgeSpec(service, CONTROL_WORLD))
    provider = Provider(GzWorldControl, GzBoolean(data=True))
    rig.gazebo(native=native).advertise_service(
        service,
        respell("gz.msgs.WorldControl", native),
        respell("gz.msgs.Boolean", native),
        provider,
    )
    response = call(world, ControlWorld, service, control_request())
    assert response.success is True
    (seen,) = provider.requests
    assert (seen.pause, seen.multi_step, seen.reset.model_only) == (True, 7, True)
    assert not seen.reset.all
    (status,) = StatusTracker(rig.bridge).snapshot()
    assert (status.level_name, status.flow, status.why) == ("OK", "", "")


def test_the_reply_value_is_converted(rig: Rig, world: RosWorld) -> None:
    service = unique("set_pose")
    rig.add(ServiceBridgeSpec(service, "ros_gz_interfaces/srv/SetEntityPose"))
    provider = Provider(GzPose, GzBoolean(data=False))  # answered: "did not move it"
    rig.gazebo().advertise_service(service, "gz.msgs.Pose", "gz.msgs.Boolean", provider)
    request = SetEntityPose.Request()
    request.entity.name = "moved_box"
    request.pose.position.x, request.pose.position.z = 1.5, -2.25
    request.pose.orientation.w = 1.0
    assert call(world, SetEntityPose, service, request).success is False
    (seen,) = provider.requests
    assert seen.name == "moved_box"
    assert (seen.position.x, seen.position.y, seen.position.z) == (1.5, 0.0, -2.25)
    assert seen.orientation.w == 1.0
    assert rig.bridge.services[0].failures == 0  # Gazebo answered; its answer was "false"


@pytest.mark.parametrize(
    "reply", [None, RuntimeError("the handler failed")], ids=["reports-failure", "raises"]
)
def test_a_failing_provider_gives_success_false(rig: Rig, world: RosWorld, reply: Any) -> None:
    service = unique("failing")
    rig.add(ServiceBridgeSpec(service, CONTROL_WORLD))
    provider = Provider(GzWorldControl, reply)
    rig.gazebo().advertise_service(service, "gz.msgs.WorldControl", "gz.msgs.Boolean", provider)
    assert call(world, ControlWorld, service, control_request()).success is False
    assert len(provider.requests) == 1
    bridge = rig.bridge.services[0]
    assert (bridge.calls, bridge.failures) == (1, 1)


def test_no_provider_gives_success_false_after_the_timeout(rig: Rig, world: RosWorld) -> None:
    """Counted as what it is (no reply), not as a conversion error, and said in the status."""
    service = unique("absent")
    rig.add(ServiceBridgeSpec(service, CONTROL_WORLD))
    assert call(world, ControlWorld, service, control_request()).success is False
    bridge = rig.bridge.services[0]
    assert (bridge.calls, bridge.failures) == (1, 1)
    (status,) = StatusTracker(rig.bridge).snapshot()
    assert (status.errors, status.conversion_errors) == (1, 0)
    assert status.errors_by_reason == (("no reply", 1),)
    assert status.last_error == (
        f"no reply within {SERVICE_TIMEOUT:g} s: no Gazebo provider of {service} is known "
        "(gz service -l, ign service -l on Fortress, lists the services there are)"
    )


def test_a_provider_of_other_types_is_named_when_nothing_answers(
    make_rig: Callable[..., Rig], world: RosWorld, capfd: pytest.CaptureFixture[str]
) -> None:
    """Also logged as soon as the provider is known (it was said only once a call failed, its
    timeout later), naming the ROS type that converts to its types (found by a new user)."""
    rig = make_rig(options(service_timeout=SERVICE_TIMEOUT, explain=True))
    service = unique("other_types")
    rig.add(ServiceBridgeSpec(service, CONTROL_WORLD))
    # before any call, the status says what it waits for (it said "ok" with no provider)
    (waiting,) = StatusTracker(rig.bridge).snapshot()
    assert (waiting.level_name, waiting.flow) == ("OK", "waiting for Gazebo")
    assert waiting.message() == (
        f"waiting for Gazebo: no Gazebo provider of {service} is known (gz service -l, ign "
        "service -l on Fortress, lists the services there are)"
    )
    provider = Provider(GzPose, GzBoolean(data=True))
    rig.gazebo().advertise_service(service, "gz.msgs.Pose", "gz.msgs.Boolean", provider)
    wait_until(lambda: bool(rig.gz.service_info(service)), "the provider in discovery")
    capfd.readouterr()
    for _ in range(2):
        world.run(rig.bridge.explain)
    why = (
        f"the Gazebo providers of {service} take gz.msgs.Pose/gz.msgs.Boolean, not "
        f"gz.msgs.WorldControl/gz.msgs.Boolean, the only types {CONTROL_WORLD} converts to; "
        "bridge the service with ros_gz_interfaces/srv/SetEntityPose, or make the provider "
        "take these"
    )
    warned = [line for line in capfd.readouterr().err.splitlines() if line.startswith("[WARN]")]
    assert len(warned) == 1, warned  # once, not at every look
    assert warned[0].endswith(f"{rig.bridge.services[0].describe()}: waiting for Gazebo: {why}")
    assert call(world, ControlWorld, service, control_request()).success is False
    assert provider.requests == []
    (status,) = StatusTracker(rig.bridge).snapshot()
    assert (status.level_name, status.fault) == ("WARN", True)  # a misconfiguration
    assert status.why.startswith(f"the Gazebo providers of {service} take gz.msgs.Pose/")
    assert status.last_error == f"no reply within {SERVICE_TIMEOUT:g} s: {why}"


def test_closing_answers_the_waiting_calls(make_rig: Callable[..., Rig], world: RosWorld) -> None:
    """A call waiting for Gazebo when the bridge closes (Ctrl-C) is answered success=false at
    once, not left to its client's patience; the Gazebo node's closing then ends the call as a
    timeout, after the bridge's executor is gone, and nothing raises."""
    rig = make_rig(options(service_timeout=30.0))
    service = unique("closing")
    rig.add(ServiceBridgeSpec(service, CONTROL_WORLD))
    bridge = rig.bridge.services[0]
    client = world.run(lambda: world.node.create_client(ControlWorld, service))
    wait_until(client.service_is_ready, f"the service {service}")
    future = world.run(lambda: client.call_async(control_request()))
    wait_until(lambda: bridge.waiting == 1, "the call waiting for Gazebo")
    (status,) = StatusTracker(rig.bridge).snapshot()
    # a waiting call is not answered yet (it counted as published before it failed)
    assert (status.received, status.published, status.errors) == (1, 0, 0)
    world.run(rig.bridge.close)
    wait_until(future.done, "the waiting call's answer")  # within WAIT, well before the 30 s
    assert future.result().success is False
    assert bridge.failures_by_reason == {"shutting down": 1}
    rig.gz.close()  # ends the call Gazebo never answered
    assert rig.gz.stats.callback_errors == 0
    world.destroy(client)


def test_a_request_not_converted_is_a_conversion_error(rig: Rig, world: RosWorld) -> None:
    service = unique("not_converted")
    rig.add(ServiceBridgeSpec(service, "ros_gz_interfaces/srv/SetEntityPose"))
    request = SetEntityPose.Request()
    request.entity.id = 2**32  # the gz Pose id is a uint32
    assert call(world, SetEntityPose, service, request).success is False
    (status,) = StatusTracker(rig.bridge).snapshot()
    assert (status.errors, status.conversion_errors) == (1, 1)
    assert status.last_error.startswith("request not converted: ")


def test_a_request_that_cannot_be_converted_never_reaches_gazebo(rig: Rig, world: RosWorld) -> None:
    service = unique("bad_id")
    rig.add(ServiceBridgeSpec(service, "ros_gz_interfaces/srv/SetEntityPose"))
    provider = Provider(GzPose, GzBoolean(data=True))
    rig.gazebo().advertise_service(service, "gz.msgs.Pose", "gz.msgs.Boolean", provider)
    request = SetEntityPose.Request()
    request.entity.id = 2**32  # the gz Pose id is a uint32
    assert call(world, SetEntityPose, service, request).success is False
    assert provider.requests == []


def take_response(client: Any) -> tuple[int, Any]:
    """The next response the client has, as (sequence number of its request, response)."""
    deadline = time.monotonic() + WAIT + SERVICE_TIMEOUT
    while time.monotonic() < deadline:
        with client.handle:
            header, response = client.handle.take_response(ControlWorld.Response)
        if header is not None:
            return header.request_id.sequence_number, response
        time.sleep(0.005)
    pytest.fail("no response")


def test_each_call_is_answered_exactly_once(rig: Rig, world: RosWorld) -> None:
    """Responses of one service come in order, so a second answer to a call would be taken
    before the answer to the next one. The C++ bridge answers a call whose Gazebo reply
    comes after the timeout twice; here the late reply is dropped."""
    service = unique("once")
    rig.add(ServiceBridgeSpec(service, CONTROL_WORLD))
    caller = world.create_node(f"core_caller_{service.rsplit('_', 1)[-1]}")  # not spun
    late = threading.Event()

    class HeldOnce(Provider):
        """Holds its first request until the test has the timeout's answer."""

        def __call__(self, payload: bytes) -> tuple[bool, bytes]:
            if not self.requests:
                late.wait(WAIT)
            return super().__call__(payload)

    try:
        client = caller.create_client(ControlWorld, service)
        assert client.wait_for_service(timeout_sec=WAIT)
        absent = client.handle.send_request(control_request())
        assert take_response(client) == (absent, ControlWorld.Response(success=False))

        provider = HeldOnce(GzWorldControl, GzBoolean(data=True))
        rig.gazebo().advertise_service(service, "gz.msgs.WorldControl", "gz.msgs.Boolean", provider)
        held = client.handle.send_request(control_request())
        assert take_response(client) == (held, ControlWorld.Response(success=False))
        late.set()  # Gazebo's reply to the held call comes now, after the timeout
        served = client.handle.send_request(control_request())
        assert take_response(client) == (served, ControlWorld.Response(success=True))
        assert len(provider.requests) == 2
    finally:
        late.set()
        caller.destroy_node()
    (status,) = StatusTracker(rig.bridge).snapshot()
    assert (status.direction, status.ros_name) == ("service", service)
    assert (status.received, status.published, status.errors) == (3, 1, 2)


def test_calls_past_max_queued_bytes_are_answered_at_once(
    make_rig: Callable[..., Rig], world: RosWorld
) -> None:
    """A bridge whose waiting calls may hold 2.5 MB takes five calls of 1 MB each for a
    provider that never answers: two wait for Gazebo (its timeout), the other three are
    answered ``success=false`` while those two still wait, and counted (before, all five
    waited, holding 5 MB)."""
    rig = make_rig(options(service_timeout=WAIT, max_queued_bytes=2_500_000))
    service = unique("held_bytes")
    rig.add(ServiceBridgeSpec(service, "ros_gz_interfaces/srv/SetEntityPose"))
    bridge = rig.bridge.services[0]
    request = SetEntityPose.Request()
    request.entity.name = "x" * 1_000_000
    client = world.run(lambda: world.node.create_client(SetEntityPose, service))
    try:
        wait_until(client.service_is_ready, f"the service {service}")
        futures = [world.run(lambda: client.call_async(request)) for _ in range(5)]
        wait_until(lambda: sum(f.done() for f in futures) == 3, "three calls answered at once")
        assert bridge.waiting == 2
        assert [f.result().success for f in futures if f.done()] == [False] * 3
        assert (bridge.refused_over_bytes, bridge.held.calls) == (3, 2)
        assert bridge.held.held > 2_000_000
    finally:
        world.destroy(client)
    assert bridge.failures == 3


def test_held_bytes_always_lets_one_call_through() -> None:
    """The budget of a service bridge's waiting calls (core/services.py): requests and kept
    replies count until their call is answered; one call alone passes whatever its size."""
    held = HeldBytes(1000)
    assert held.admit(5000)  # alone: let through
    assert not held.admit(1)  # over the budget while it waits
    assert held.keep(3000)  # its own reply, alone: kept
    held.release(8000)
    assert (held.calls, held.held) == (0, 0)
    assert held.admit(400)
    assert held.admit(500)
    assert not held.keep(200)  # a reply past the budget with another call waiting
    assert held.keep(100)
    held.release(500)
    held.release(500)
    assert (held.calls, held.held) == (0, 0)


def test_a_response_whose_client_is_never_discovered_is_given_up_and_counted(
    rig: Rig, world: RosWorld
) -> None:
    """A client whose response reader the service's writer cannot match (transient_local
    durability) still gets its request through; rmw then times out sending the response, which
    rclpy only warns about and drops. The bridge holds it, tries again until its patience runs
    out, then counts it as dropped (status) and says why."""
    service = unique("never_found")
    rig.add(ServiceBridgeSpec(service, CONTROL_WORLD))
    rig.gazebo().advertise_service(
        service, "gz.msgs.WorldControl", "gz.msgs.Boolean", Provider(GzWorldControl, GzBoolean())
    )
    bridge = rig.bridge.services[0]
    late = rig.bridge._side_node().late_responses
    late.patience = 0.5
    unmatched = QoSProfile(depth=10, durability=DurabilityPolicy.TRANSIENT_LOCAL)
    client = world.run(
        lambda: world.node.create_client(ControlWorld, service, qos_profile=unmatched)
    )
    try:
        future = world.run(lambda: client.call_async(control_request()))
        wait_until(lambda: bridge.calls == 1, "the request taken by the bridge")
        wait_until(lambda: late.held == 1, "the response held")
        wait_until(lambda: bridge.unanswered == 1, "the response given up", timeout=WAIT)
        assert late.held == 0
        assert not future.done()
    finally:
        world.destroy(client)
    (status,) = StatusTracker(rig.bridge).snapshot()
    assert (status.received, status.published, status.dropped) == (1, 0, 1)
    assert bridge.late_answers == 0


class Warnings:
    """Stands in for a service bridge's logger: keeps its warnings."""

    def __init__(self) -> None:
        self.lines: list[str] = []

    def warning(self, line: str) -> None:
        self.lines.append(line)

    def info(self, line: str) -> None:
        """Late answers are told at INFO; not what these tests count."""


def test_failed_and_given_up_calls_are_counted_in_full_and_told_once_per_period(
    rig: Rig, world: RosWorld
) -> None:
    """A provider that fails every call, called three times, and three responses given up:
    every one counted, each kind told once per period (a client calling fast must not turn
    the log into one line per call)."""
    service = unique("failing_often")
    rig.add(ServiceBridgeSpec(service, CONTROL_WORLD))
    provider = Provider(GzWorldControl, None)
    rig.gazebo().advertise_service(service, "gz.msgs.WorldControl", "gz.msgs.Boolean", provider)
    bridge = rig.bridge.services[0]
    warnings = Warnings()
    bridge._logger = warnings  # type: ignore[assignment]
    for _ in range(3):
        assert call(world, ControlWorld, service, control_request()).success is False
    for _ in range(3):
        bridge.not_answered(10.0, "its client was not discovered")
    assert (bridge.failures, bridge.unanswered) == (3, 3)
    assert len(warnings.lines) == 2, warnings.lines
    assert "Gazebo reported failure; 1 failed so far" in warnings.lines[0]
    assert "given up after 10.0 s: its client was not discovered; 1 given up" in warnings.lines[1]


def test_a_ros_client_of_another_service_type_is_said_once(
    make_rig: Callable[..., Rig], world: RosWorld, capfd: pytest.CaptureFixture[str]
) -> None:
    """A DeleteEntity client of a ControlWorld service never sees it: its wait_for_service
    timed out and the bridge said nothing (found by a new user)."""
    rig = make_rig(options(service_timeout=SERVICE_TIMEOUT, explain=True))
    service = unique("client_type")
    rig.add(ServiceBridgeSpec(service, CONTROL_WORLD))
    context = Context()
    rclpy.init(context=context)
    other = rclpy.create_node(f"core_client_{uuid.uuid4().hex[:8]}", context=context)
    try:
        other.create_client(DeleteEntity, service)
        delete = "ros_gz_interfaces/srv/DeleteEntity"
        wait_until(
            lambda: delete in dict(rig.node.get_service_names_and_types()).get(service, []),
            "the client in the graph",
        )
        capfd.readouterr()
        for _ in range(2):
            world.run(rig.bridge.explain)
        warned = [line for line in capfd.readouterr().err.splitlines() if "[WARN]" in line]
        assert len(warned) == 1, warned  # once, not at every look
        assert warned[0].endswith(
            f"{rig.bridge.services[0].describe()}: a ROS node uses {service} with {delete}, but "
            f"the bridge serves {CONTROL_WORLD}: a client of another type never sees the "
            f"service (its wait_for_service times out); have it use {CONTROL_WORLD}, or bridge "
            "the service with its type"
        )
    finally:
        other.destroy_node()
        try_shutdown(context=context)


def test_a_provider_that_went_silent_during_the_call_is_said_so(rig: Rig, world: RosWorld) -> None:
    """The no-reply text said no provider was known, of a provider that got the request and
    went silent (a simulator frozen for 7 s, found by a new user)."""
    service = unique("went_silent")
    rig.add(ServiceBridgeSpec(service, CONTROL_WORLD))
    entered, released = threading.Event(), threading.Event()

    def stuck(_payload: bytes) -> tuple[bool, bytes]:
        entered.set()
        released.wait(WAIT)
        return True, GzBoolean(data=True).SerializeToString()

    offer = rig.gazebo().advertise_service(
        service, "gz.msgs.WorldControl", "gz.msgs.Boolean", stuck
    )
    wait_until(lambda: bool(rig.gz.service_info(service)), "the provider in discovery")
    client = world.run(lambda: world.node.create_client(ControlWorld, service))
    try:
        wait_until(client.service_is_ready, f"the service {service}")
        future = world.run(lambda: client.call_async(control_request()))
        wait_until(entered.is_set, "the request at the provider")
        offer.close()  # as discovery forgets a process silent for 3 s
        wait_until(future.done, f"a response from {service}", timeout=WAIT)
    finally:
        released.set()
        world.destroy(client)
    assert future.result().success is False
    (status,) = StatusTracker(rig.bridge).snapshot()
    assert status.last_error == (
        f"no reply within {SERVICE_TIMEOUT:g} s: the Gazebo provider known when the call was "
        "made went silent (a simulator busy or stopped: discovery forgets a process silent for "
        "3 s)"
    )

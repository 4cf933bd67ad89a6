"""Service bridges: ROS clients calling real ign-transport 11 services through the bridge.

One bridge process serves every case: ControlWorld in the explicit CLI form (Fortress type
names, as a Fortress Gazebo needs), DeleteEntity/SetEntityPose/SpawnEntity, and one entry
from a YAML file. The peer's ``reply`` mode prints each request it gets, so the converted
request values are checked where Gazebo sees them.
"""

from __future__ import annotations

import os
import signal
import threading
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
import rclpy
from rclpy.qos import QoSProfile
from ros_gz_interfaces.msg import Entity
from ros_gz_interfaces.srv import ControlWorld, DeleteEntity, SetEntityPose, SpawnEntity

from testing.behaviour_harness import (
    WAIT,
    RosSide,
    ros_side,
    start_bridge,
    started,
)
from testing.gzpeer import PeerProcess, require_peer, start_peer, unique_name, wait_for_line

__all__ = ["ros_side", "started"]

pytestmark = [pytest.mark.ros, pytest.mark.peer]

WORLD_CONTROL = "ignition.msgs.WorldControl"
BOOLEAN = "ignition.msgs.Boolean"
SERVICE_TIMEOUT = 1.0
#: (ROS service type, Gazebo request type) of the CLI service bridges, by key.
CLI_SERVICES = {
    "control": ("ControlWorld", WORLD_CONTROL),
    "storm": ("ControlWorld", WORLD_CONTROL),
    "storm_absent": ("ControlWorld", WORLD_CONTROL),
    "control_fail": ("ControlWorld", WORLD_CONTROL),
    "control_absent": ("ControlWorld", WORLD_CONTROL),
    "delete": ("DeleteEntity", "ignition.msgs.Entity"),
    "set_pose": ("SetEntityPose", "ignition.msgs.Pose"),
    "spawn": ("SpawnEntity", "ignition.msgs.EntityFactory"),
}


@pytest.fixture(scope="module")
def service_bridge(
    tmp_path_factory: pytest.TempPathFactory,
) -> Iterator[tuple[dict[str, str], PeerProcess]]:
    """Service names by key ("control", ..., "yaml") of one running bridge, and the bridge."""
    require_peer()
    names = {key: unique_name(f"svc_{key}") for key in (*CLI_SERVICES, "yaml")}
    config = Path(tmp_path_factory.mktemp("services") / "services.yaml")
    config.write_text(
        f"- service_name: {names['yaml']}\n"
        "  ros_type_name: ros_gz_interfaces/srv/ControlWorld\n"
        f"  gz_req_type_name: {WORLD_CONTROL}\n"
        f"  gz_rep_type_name: {BOOLEAN}\n"
    )
    args = [
        f"{names[key]}@ros_gz_interfaces/srv/{ros_type}@{gz_request}@{BOOLEAN}"
        for key, (ros_type, gz_request) in CLI_SERVICES.items()
    ]
    bridge = start_bridge(
        *args,
        ros_args=["-p", f"config_file:={config}", "-p", f"service_timeout:={SERVICE_TIMEOUT}"],
        creating=len(names),
    )
    yield names, bridge
    bridge.stop()


@pytest.fixture(scope="module")
def services(service_bridge: tuple[dict[str, str], PeerProcess]) -> dict[str, str]:
    return service_bridge[0]


def start_replier(
    started: list[PeerProcess], service: str, request_type: str, *flags: str
) -> PeerProcess:
    peer = start_peer("reply", service, request_type, BOOLEAN, "60", *flags)
    started.append(peer)
    wait_for_line(peer, r"^READY$")
    return peer


def call(ros_side: RosSide, srv_type: Any, service: str, request: Any) -> Any:
    """One call through a fresh client; fails the test if no response comes within WAIT."""
    client = ros_side.run(lambda: ros_side.node.create_client(srv_type, service))
    try:
        deadline = time.monotonic() + WAIT
        while not client.service_is_ready():
            if time.monotonic() > deadline:
                pytest.fail(f"service {service} never appeared")
            time.sleep(0.05)
        future = ros_side.run(lambda: client.call_async(request))
        while not future.done():
            if time.monotonic() > deadline + WAIT:
                pytest.fail(f"no response from {service}")
            time.sleep(0.02)
        return future.result()
    finally:
        ros_side.destroy(client)


def call_until_served(
    ros_side: RosSide, peer: PeerProcess, srv_type: Any, service: str, request: Any
) -> tuple[Any, str]:
    """Call until the peer printed a request (the bridge may not have discovered it yet).

    Returns the response of that call and the peer's ``REQUEST`` line.
    """
    deadline = time.monotonic() + WAIT
    while time.monotonic() < deadline:
        response = call(ros_side, srv_type, service, request)
        if served := [line for line in peer.output().splitlines() if line.startswith("REQUEST")]:
            return response, served[-1]
    pytest.fail(f"the Gazebo service {service} never got a request; output:\n{peer.output()}")


def control_request() -> Any:
    request = ControlWorld.Request()
    request.world_control.pause = True
    request.world_control.multi_step = 7
    request.world_control.reset.model_only = True
    return request


def test_control_world_reaches_gazebo_and_succeeds(
    services: dict[str, str], ros_side: RosSide, started: list[PeerProcess]
) -> None:
    peer = start_replier(started, services["control"], WORLD_CONTROL)
    response, request = call_until_served(
        ros_side, peer, ControlWorld, services["control"], control_request()
    )
    assert response.success is True
    assert request.startswith(f"REQUEST {WORLD_CONTROL} ")
    assert "pause: true" in request
    assert "multi_step: 7" in request
    assert "model_only: true" in request


def test_control_world_failure_in_gazebo_is_success_false(
    service_bridge: tuple[dict[str, str], PeerProcess],
    ros_side: RosSide,
    started: list[PeerProcess],
) -> None:
    services, bridge = service_bridge
    peer = start_replier(started, services["control_fail"], WORLD_CONTROL, "--fail")
    response, request = call_until_served(
        ros_side, peer, ControlWorld, services["control_fail"], control_request()
    )
    assert response.success is False
    assert "multi_step: 7" in request
    # under the bridge's node name (it was its side node's, _ros_gz_bridge_side)
    said = wait_for_line(bridge, rf"{services['control_fail']} .*Gazebo reported failure").string
    assert "[ros_gz_bridge]: ROS->GZ service [" in said


def test_no_gazebo_service_gives_exactly_one_failure_response(
    services: dict[str, str], ros_side: RosSide
) -> None:
    # A node outside the spinning executor, so this test takes the responses itself.
    node = rclpy.create_node(
        f"svc_counter_{int(time.time() * 1000) % 100000}", context=ros_side.context
    )
    try:
        client = node.create_client(ControlWorld, services["control_absent"])
        assert client.wait_for_service(timeout_sec=WAIT)
        client.call_async(control_request())
        responses = []
        listen_until = time.monotonic() + SERVICE_TIMEOUT + 2.0
        while time.monotonic() < listen_until:
            with client.handle:
                header, response = client.handle.take_response(ControlWorld.Response)
            if header is not None:
                responses.append(response)
            time.sleep(0.02)
        assert [response.success for response in responses] == [False]
    finally:
        node.destroy_node()


def test_yaml_service_entry_is_bridged(
    services: dict[str, str], ros_side: RosSide, started: list[PeerProcess]
) -> None:
    peer = start_replier(started, services["yaml"], WORLD_CONTROL)
    response, request = call_until_served(
        ros_side, peer, ControlWorld, services["yaml"], control_request()
    )
    assert response.success is True
    assert "pause: true" in request


def test_delete_entity_request_as_gazebo_sees_it(
    services: dict[str, str], ros_side: RosSide, started: list[PeerProcess]
) -> None:
    peer = start_replier(started, services["delete"], "ignition.msgs.Entity")
    request = DeleteEntity.Request()
    request.entity.name = "doomed_box"
    request.entity.type = Entity.MODEL
    response, seen = call_until_served(ros_side, peer, DeleteEntity, services["delete"], request)
    assert response.success is True
    assert seen.startswith("REQUEST ignition.msgs.Entity ")
    assert 'name: "doomed_box"' in seen
    assert "type: MODEL" in seen


def test_set_entity_pose_request_as_gazebo_sees_it(
    services: dict[str, str], ros_side: RosSide, started: list[PeerProcess]
) -> None:
    peer = start_replier(started, services["set_pose"], "ignition.msgs.Pose")
    request = SetEntityPose.Request()
    request.entity.name = "moved_box"
    request.pose.position.x = 1.5
    request.pose.position.z = -2.25
    request.pose.orientation.w = 1.0
    response, seen = call_until_served(ros_side, peer, SetEntityPose, services["set_pose"], request)
    assert response.success is True
    assert seen.startswith("REQUEST ignition.msgs.Pose ")
    assert 'name: "moved_box"' in seen
    assert "x: 1.5" in seen
    assert "z: -2.25" in seen


def test_spawn_entity_request_as_gazebo_sees_it(
    services: dict[str, str], ros_side: RosSide, started: list[PeerProcess]
) -> None:
    peer = start_replier(started, services["spawn"], "ignition.msgs.EntityFactory")
    request = SpawnEntity.Request()
    request.entity_factory.name = "new_box"
    request.entity_factory.sdf_filename = "model://box"
    request.entity_factory.allow_renaming = True
    request.entity_factory.pose.position.y = 3.0
    response, seen = call_until_served(ros_side, peer, SpawnEntity, services["spawn"], request)
    assert response.success is True
    assert seen.startswith("REQUEST ignition.msgs.EntityFactory ")
    assert 'name: "new_box"' in seen
    assert 'sdf_filename: "model://box"' in seen
    assert "allow_renaming: true" in seen
    assert "y: 3" in seen


#: Clients calling at once in the storm tests (issue 14: 36 of 50 went unanswered before).
STORM = 50
#: Every client's reader sees every client's responses on the shared reply topic; with rclpy's
#: default depth of 10, a client whose own response was pushed out by others' would look
#: unanswered, so each keeps them all.
CLIENT_QOS = QoSProfile(depth=STORM * 2)


#: Calls served one after another without Gazebo would take STORM timeouts: every one answered
#: within half that shows the bridge waits for them together, however busy the machine.
STORM_DEADLINE = STORM * SERVICE_TIMEOUT / 2


def call_at_once(context: Any, service: str) -> dict[int, list[tuple[float, bool]]]:
    """``STORM`` clients call ``service`` at the same moment; each client's responses, with the
    seconds from the calls to their arrival. The node is not spun: responses are taken here,
    until every client has one (``STORM_DEADLINE`` at most), then for a service timeout more,
    in which a second answer to a call would show."""
    node = rclpy.create_node(f"svc_storm_{int(time.time() * 1000) % 100000}", context=context)
    try:
        clients = [
            node.create_client(ControlWorld, service, qos_profile=CLIENT_QOS) for _ in range(STORM)
        ]
        for client in clients:
            assert client.wait_for_service(timeout_sec=WAIT)
        start = time.monotonic()
        for client in clients:
            client.call_async(control_request())
        answers: dict[int, list[tuple[float, bool]]] = {}
        listen_until = start + STORM_DEADLINE
        all_answered = False
        while time.monotonic() < listen_until:
            for index, client in enumerate(clients):
                with client.handle:
                    header, response = client.handle.take_response(ControlWorld.Response)
                if header is not None:
                    answers.setdefault(index, []).append(
                        (time.monotonic() - start, response.success)
                    )
            if not all_answered and len(answers) == STORM:
                all_answered = True
                listen_until = time.monotonic() + SERVICE_TIMEOUT
            time.sleep(0.01)
        return answers
    finally:
        node.destroy_node()


def test_a_storm_without_gazebo_gets_every_answer_once_within_the_timeout(
    services: dict[str, str], ros_side: RosSide
) -> None:
    answers = call_at_once(ros_side.context, services["storm_absent"])
    assert sorted(answers) == list(range(STORM)), (
        f"unanswered after {STORM_DEADLINE:g} s: {STORM - len(answers)}"
    )
    assert all(len(got) == 1 for got in answers.values()), answers
    assert {ok for ((_, ok),) in answers.values()} == {False}
    # Each answered when its own timeout ran out, not before (the bridge cannot know sooner
    # that Gazebo will not answer); all of them within STORM_DEADLINE: together.
    earliest = min(elapsed for ((elapsed, _),) in answers.values())
    assert earliest >= SERVICE_TIMEOUT, f"an answer came after {earliest:.2f} s"


def test_a_storm_with_gazebo_is_served_in_full(
    services: dict[str, str], ros_side: RosSide, started: list[PeerProcess]
) -> None:
    peer = start_replier(started, services["storm"], WORLD_CONTROL)
    call_until_served(ros_side, peer, ControlWorld, services["storm"], control_request())
    answers = call_at_once(ros_side.context, services["storm"])
    assert sorted(answers) == list(range(STORM)), f"unanswered: {STORM - len(answers)}"
    assert all(len(got) == 1 for got in answers.values()), answers
    assert {ok for ((_, ok),) in answers.values()} == {True}


def test_a_first_call_made_the_moment_the_service_is_discoverable_is_answered(
    ros_side: RosSide, started: list[PeerProcess]
) -> None:
    """A fresh bridge, a client already waiting: its one call, made as soon as the service is
    ready, reaches the Fortress service once and is answered (issue 23: a first request or reply
    lost would be answered only after Fast DDS resends it, or not at all)."""
    service = unique_name("svc_first_call")
    peer = start_replier(started, service, WORLD_CONTROL)
    client = ros_side.run(lambda: ros_side.node.create_client(ControlWorld, service))
    entry = f"{service}@ros_gz_interfaces/srv/ControlWorld@{WORLD_CONTROL}@{BOOLEAN}"
    bridge = start_bridge(entry)
    started.append(bridge)
    try:
        deadline = time.monotonic() + WAIT
        while not client.service_is_ready():
            assert time.monotonic() < deadline, f"service {service} never appeared"
            time.sleep(0.001)
        future = ros_side.run(lambda: client.call_async(control_request()))
        while not future.done():
            assert time.monotonic() < deadline + WAIT, (
                f"no response from {service}; the bridge printed:\n{bridge.output()}\n"
                f"the Fortress service printed:\n{peer.output()}"
            )
            time.sleep(0.01)
    finally:
        ros_side.destroy(client)
    assert future.result().success
    requests = [line for line in peer.output().splitlines() if line.startswith("REQUEST")]
    assert len(requests) == 1  # sent to Gazebo once: no retry
    assert "multi_step: 7" in requests[0]


def test_a_call_to_a_provider_unreachable_for_two_seconds_is_served_when_it_is_back(
    ros_side: RosSide, started: list[PeerProcess]
) -> None:
    """The request to a provider the bridge could not connect to yet was given up after 1 s
    and the call failed at its timeout, 8 s later, the provider back long before (found by a
    new user: a simulator busy for a moment)."""
    service = unique_name("svc_frozen")
    bridge = start_bridge(
        f"{service}@ros_gz_interfaces/srv/ControlWorld@{WORLD_CONTROL}@{BOOLEAN}",
        ros_args=["-p", "service_timeout:=8"],
        creating=1,
    )
    started.append(bridge)
    peer = start_replier(started, service, WORLD_CONTROL)
    time.sleep(1.0)  # the bridge hears its ADVERTISE; no call has connected to it yet
    os.kill(peer.pid, signal.SIGSTOP)
    resume = threading.Timer(2.0, os.kill, (peer.pid, signal.SIGCONT))
    resume.start()
    try:
        response = call(ros_side, ControlWorld, service, control_request())
    finally:
        resume.join()
    assert response.success is True, bridge.output()
    wait_for_line(peer, r"^REQUEST ")

"""A service bridge and ``image_bridge`` over Zenoh (gz-transport 15), end to end.

The Gazebo side is our ``ZenohGzNode`` in a process of its own: ``e2e_zenoh_extras.py`` offers
a ``gz.msgs.WorldControl``/``gz.msgs.Boolean`` service, ``e2e_zenoh_gazebo.py`` publishes a
``gz.msgs.Image``. The bridges are the real console scripts with
``GZ_TRANSPORT_IMPLEMENTATION=zenoh`` and ``GZ_TRANSPORT_ZENOH_CONFIG_OVERRIDE`` set as in
``test_zenoh_e2e.py``: peer mode, the bridge listening on a free ``tcp/127.0.0.1`` port, the
Gazebo side connecting to it, no scouting. The ROS side is rclpy in this process.
"""

from __future__ import annotations

import json
import time
from collections.abc import Iterator
from typing import Any

import pytest
from google.protobuf import text_format
from ros_gz_interfaces.srv import ControlWorld
from sensor_msgs.msg import Image

from ros_gz_bridge_py.msgs import message_class
from testing.behaviour_harness import WAIT, RosSide, ros_side
from testing.e2e_harness import PARAMETER_BRIDGE, ProcessGroup, lines
from testing.gzpeer import PeerProcess, unique_name, wait_for_line
from testing.loopback import free_port, zenoh_env
from tests.bridge.image_frames import rgb_frame
from tests.bridge.test_zenoh_e2e import GAZEBO_SIDE, HERE

__all__ = ["ros_side"]

pytestmark = [pytest.mark.ros]

SERVICE_SIDE = HERE / "e2e_zenoh_extras.py"
IMAGE_BRIDGE = PARAMETER_BRIDGE.with_name("image_bridge")
#: Lifetime of the Gazebo-side processes (they are stopped at test end well before).
GAZEBO_SECONDS = "60"
WIDTH, HEIGHT = 8, 6
SERVICE_TIMEOUT = 1.0
WORLD_CONTROL = "gz.msgs.WorldControl"


@pytest.fixture
def group() -> Iterator[ProcessGroup]:
    """Processes of one test, stopped at its end."""
    processes = ProcessGroup()
    yield processes
    processes.stop()


def peer_envs() -> tuple[dict[str, str], dict[str, str]]:
    """(bridge, Gazebo side) environments: the bridge listens, Gazebo connects, loopback only."""
    endpoint = f"tcp/127.0.0.1:{free_port()}"
    return (
        zenoh_env("peer", listen=[endpoint], connect=[]),
        zenoh_env("peer", listen=[], connect=[endpoint]),
    )


def wait_service(ros: RosSide, client: Any, service: str) -> None:
    deadline = time.monotonic() + WAIT
    while not client.service_is_ready():
        if time.monotonic() > deadline:
            pytest.fail(f"service {service} never appeared in ROS")
        time.sleep(0.05)


def call(ros: RosSide, client: Any, request: Any, timeout: float) -> Any:
    """One call; fails the test if no response comes within ``timeout``."""
    future = ros.run(lambda: client.call_async(request))
    deadline = time.monotonic() + timeout
    while not future.done():
        if time.monotonic() > deadline:
            pytest.fail("no response from the bridge")
        time.sleep(0.02)
    return future.result()


def control_request() -> Any:
    request = ControlWorld.Request()
    request.world_control.pause = True
    request.world_control.multi_step = 7
    return request


def test_control_world_service_over_zenoh(group: ProcessGroup, ros_side: RosSide) -> None:
    served, absent = unique_name("zsvc") + "/control", unique_name("zsvc_absent") + "/control"
    bridge_env, gazebo_env = peer_envs()
    bridge = group.start(
        [
            str(PARAMETER_BRIDGE),
            f"{served}@ros_gz_interfaces/srv/ControlWorld",
            f"{absent}@ros_gz_interfaces/srv/ControlWorld",
            "--ros-args",
            "-p",
            f"service_timeout:={SERVICE_TIMEOUT}",
        ],
        env=bridge_env,
    )
    gazebo = group.python(SERVICE_SIDE, served, GAZEBO_SECONDS, env=gazebo_env)
    wait_for_line(gazebo, "^READY$", timeout=15)
    assert lines(gazebo, "NODE ") == ["ZenohGzNode"]

    client = ros_side.run(lambda: ros_side.node.create_client(ControlWorld, served))
    absent_client = ros_side.run(lambda: ros_side.node.create_client(ControlWorld, absent))
    try:
        wait_service(ros_side, client, served)
        # Until the bridge discovered the Gazebo offer, a call times out (success=False).
        deadline = time.monotonic() + WAIT
        response = None
        while not lines(gazebo, "REQUEST "):
            if time.monotonic() > deadline:
                pytest.fail(
                    f"Gazebo never got a request; bridge:\n{bridge.output()}\n"
                    f"gazebo side:\n{gazebo.output()}"
                )
            response = call(ros_side, client, control_request(), WAIT)
        assert response is not None
        assert response.success is True, bridge.output()
        request = text_format.Parse(lines(gazebo, "REQUEST ")[-1], message_class(WORLD_CONTROL)())
        assert request.pause is True
        assert request.multi_step == 7

        wait_service(ros_side, absent_client, absent)
        started = time.monotonic()
        failed = call(ros_side, absent_client, control_request(), SERVICE_TIMEOUT + WAIT)
        assert failed.success is False
        assert time.monotonic() - started >= SERVICE_TIMEOUT * 0.9
        time.sleep(SERVICE_TIMEOUT)  # room for a second answer, which must not come
        failures = [line for line in lines(bridge, "") if absent in line and "no reply" in line]
        assert len(failures) == 1, bridge.output()
    finally:
        ros_side.destroy(client)
        ros_side.destroy(absent_client)


def test_image_bridge_over_zenoh(group: ProcessGroup, ros_side: RosSide) -> None:
    topic = unique_name("zimage") + "/image"
    data = bytes((index * 7 + 3) % 256 for index in range(WIDTH * HEIGHT * 3))
    frame = rgb_frame(WIDTH, HEIGHT, frame_id="zcam", data=data)
    bridge_env, gazebo_env = peer_envs()
    bridge: PeerProcess = group.start([str(IMAGE_BRIDGE), topic], env=bridge_env)
    inbox, _subscription = ros_side.subscribe(Image, topic)
    spec = {
        "publish": [[topic, "gz.msgs.Image", text_format.MessageToString(frame, as_one_line=True)]],
        "seconds": float(GAZEBO_SECONDS),
    }
    gazebo = group.python(GAZEBO_SIDE, json.dumps(spec), env=gazebo_env)
    wait_for_line(gazebo, "^READY$", timeout=15)
    assert lines(gazebo, "NODE ") == ["ZenohGzNode"]
    if not inbox.holds_within(bool, 2 * WAIT):
        pytest.fail(f"no image in ROS; bridge:\n{bridge.output()}\ngazebo:\n{gazebo.output()}")
    image, _ = inbox.items()[0]
    assert image.encoding == "rgb8"
    assert (image.width, image.height, image.step) == (WIDTH, HEIGHT, 24)
    assert image.header.frame_id == "zcam"
    assert bytes(image.data) == data

"""What start-up holds back comes a moment later (docs/environment.md §3).

A real ``parameter_bridge`` process holds its node's parameter and type description services
until its channels exist; they then answer as rclpy's own do. Its helper nodes offer neither.
Renaming the bridge's node (``-r __node:=``) leaves the helper nodes their own names, which
are hidden (they start with ``_``), so that ROS tools list one node, as with the C++ bridge.
Loading the bridge for String entries imports neither numpy nor asyncio, the two largest
imports a run of such entries does not need; the collector paused during start-up runs again.
"""

from __future__ import annotations

import subprocess
import sys
import textwrap
import uuid

import pytest
from rcl_interfaces.srv import ListParameters

from testing.behaviour_harness import (
    STRING,
    WAIT,
    RosSide,
    ros_side,
    start_bridge,
    started,
)
from testing.gzpeer import PeerProcess, unique_name, wait_until
from tests.rclpy_services import PARAMETER_SERVICES

__all__ = ["ros_side", "started"]


def services_by_node(ros: RosSide) -> dict[str, set[str]]:
    """Every node of the graph in the root namespace -> the last part of its services' names."""

    def read() -> dict[str, set[str]]:
        graph: dict[str, set[str]] = {}
        for name, namespace in ros.node.get_node_names_and_namespaces():
            if namespace != "/":
                continue
            services = ros.node.get_service_names_and_types_by_node(name, namespace)
            graph[name] = {service.rsplit("/", 1)[-1] for service, _ in services}
        return graph

    return ros.run(read)


@pytest.mark.ros
def test_the_bridge_offers_rclpys_node_services_once_its_channels_exist(
    ros_side: RosSide, started: list[PeerProcess]
) -> None:
    node_name = f"start_up_{uuid.uuid4().hex[:8]}"
    bridge = start_bridge(
        f"{unique_name('start_up')}@std_msgs/msg/String@{STRING}",
        ros_args=["-r", f"__node:={node_name}"],
        creating=2,
    )
    started.append(bridge)
    wait_until(
        lambda: services_by_node(ros_side).get(node_name, set()) >= PARAMETER_SERVICES,
        WAIT,
        f"{node_name}'s parameter and type description services",
    )
    helpers = {
        name: services
        for name, services in services_by_node(ros_side).items()
        if name.startswith(f"_{node_name}_")
    }
    assert helpers, "a bidirectional entry makes helper nodes (side, native), named apart"
    names = ros_side.run(ros_side.node.get_node_names)
    assert names.count(node_name) == 1, names
    # What `ros2 node list` shows (it leaves out names that start with "_"): one node, as C++.
    assert [name for name in names if node_name in name and not name.startswith("_")] == [node_name]
    assert all(not services & PARAMETER_SERVICES for services in helpers.values()), helpers

    client = ros_side.run(
        lambda: ros_side.node.create_client(ListParameters, f"/{node_name}/list_parameters")
    )
    try:
        future = ros_side.run(lambda: client.call_async(ListParameters.Request()))
        wait_until(future.done, WAIT, "list_parameters' answer")
        names = set(future.result().result.names)
    finally:
        ros_side.destroy(client)
    assert {"config_file", "lazy", "start_type_description_service", "use_sim_time"} <= names


IMPORTS = textwrap.dedent(
    """
    import sys
    import ros_gz_bridge_py.app.parameter_bridge
    from ros_gz_bridge_py.transport import create_gz_node
    from ros_gz_bridge_py.transport.api import NodeOptions
    with create_gz_node(NodeOptions()):
        pass
    print(sorted({"numpy", "asyncio"} & set(sys.modules)))
    """
)


def test_loading_the_bridge_and_a_gazebo_node_imports_neither_numpy_nor_asyncio() -> None:
    out = subprocess.run(
        [sys.executable, "-c", IMPORTS], capture_output=True, text=True, timeout=60, check=True
    )
    assert out.stdout.strip() == "[]", out.stderr


COLLECTOR = textwrap.dedent(
    """
    import gc
    from ros_gz_bridge_py.app import startup
    frozen = gc.get_freeze_count()  # 0 on Python 3.11; 3.12 starts with some frozen
    startup.resume_collector()  # not paused: nothing
    assert gc.isenabled() and gc.get_freeze_count() == frozen
    startup.pause_collector()
    assert not gc.isenabled()
    made = [[] for _ in range(1000)]
    for _ in range(1000):
        cycle = []
        cycle.append(cycle)  # garbage only the collector frees
    del cycle
    startup.resume_collector()
    assert gc.isenabled() and gc.get_freeze_count() >= frozen + len(made)
    gc.unfreeze()  # what was frozen is listed again: no cycle among it
    assert not any(type(o) is list and len(o) == 1 and o[0] is o for o in gc.get_objects())
    startup.resume_collector()  # once only
    gc.disable()
    startup.pause_collector()  # the program's own choice: left alone
    startup.resume_collector()
    assert not gc.isenabled()
    print("ok")
    """
)


def test_the_collector_paused_for_start_up_runs_again_with_start_ups_objects_frozen() -> None:
    out = subprocess.run(
        [sys.executable, "-c", COLLECTOR], capture_output=True, text=True, timeout=60, check=False
    )
    assert out.stdout.strip() == "ok", out.stderr

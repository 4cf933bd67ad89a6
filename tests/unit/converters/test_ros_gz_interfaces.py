"""ros_gz_interfaces' pairs and its four services (docs/conversions-per-package.md §3.13, §3.14);
the messages' conversions are in test_ros_gz_interfaces_messages*.py."""

from __future__ import annotations

from typing import Any

import pytest
from ros_gz_interfaces.msg import (
    Entity,
    EntityFactory,
    WorldControl,
)
from ros_gz_interfaces.srv import ControlWorld, DeleteEntity, SetEntityPose, SpawnEntity

from ros_gz_bridge_py.converters.registry import Registry
from ros_gz_bridge_py.converters.ros_gz_interfaces import (
    PAIRS,
    SERVICES,
    control_world_request_to_gz,
    delete_entity_request_to_gz,
    set_entity_pose_request_to_gz,
    spawn_entity_request_to_gz,
)
from ros_gz_bridge_py.errors import ConversionError
from ros_gz_bridge_py.msgs import message_class
from tests.unit.converters.ros_gz_interfaces_values import (
    GzBoolean,
    GzEntity,
    assert_vector,
    entity,
    pose,
)

# --- registration ---------------------------------------------------------------------------


def test_every_pair_and_service_registers_once() -> None:
    registry = Registry()
    for pair in PAIRS:
        registry.add(pair)
    for service in SERVICES:
        registry.add_service(service)
    assert registry.gz_types_for("ros_gz_interfaces/msg/ParamVec") == [
        "gz.msgs.Param",
        "gz.msgs.Param_V",
    ]
    assert [s.ros_type for s in SERVICES] == [
        "ros_gz_interfaces/srv/ControlWorld",
        "ros_gz_interfaces/srv/DeleteEntity",
        "ros_gz_interfaces/srv/SpawnEntity",
        "ros_gz_interfaces/srv/SetEntityPose",
    ]
    for pair in PAIRS:
        assert message_class(pair.gz_type).DESCRIPTOR.full_name == pair.gz_type
        assert isinstance(pair.to_ros(message_class(pair.gz_type)()), pair.ros_class)


# --- Services -------------------------------------------------------------------------------


def test_control_world_request_converts_every_field() -> None:
    control = WorldControl(pause=True, step=False, multi_step=17, seed=4_000_000_000)
    control.reset.all = False
    control.reset.time_only = True
    control.reset.model_only = False
    control.run_to_sim_time.sec = 12
    control.run_to_sim_time.nanosec = 3_000_000_000
    gz = control_world_request_to_gz(ControlWorld.Request(world_control=control))
    assert (gz.pause, gz.step, gz.multi_step, gz.seed) == (True, False, 17, 4_000_000_000)
    assert (gz.reset.all, gz.reset.time_only, gz.reset.model_only) == (False, True, False)
    assert (gz.run_to_sim_time.sec, gz.run_to_sim_time.nsec) == (12, 3_000_000_000 - 2**32)
    assert not gz.HasField("header")


def test_control_world_request_default_has_reset_and_run_to_sim_time() -> None:
    gz = control_world_request_to_gz(ControlWorld.Request())
    assert gz.HasField("reset")
    assert gz.HasField("run_to_sim_time")
    assert gz.SerializeToString() == bytes.fromhex("2a003a00")


def test_delete_entity_request_converts_the_entity() -> None:
    gz = delete_entity_request_to_gz(DeleteEntity.Request(entity=entity(kind=Entity.MODEL)))
    assert (gz.id, gz.name, gz.type) == (9_000_000_001, "box::link", GzEntity.MODEL)


def spawn_request(**fields: Any) -> Any:
    factory = EntityFactory(name="robot", allow_renaming=True, pose=pose(3.0), **fields)
    factory.relative_to = "ground"
    return SpawnEntity.Request(entity_factory=factory)


def test_spawn_entity_request_converts_every_field() -> None:
    gz = spawn_entity_request_to_gz(spawn_request(sdf="<sdf version='1.9'/>"))
    assert (gz.name, gz.allow_renaming, gz.relative_to) == ("robot", True, "ground")
    assert gz.WhichOneof("from") == "sdf"
    assert gz.sdf == "<sdf version='1.9'/>"
    assert_vector(gz.pose.position, 3.0, 3.5, 3.25)
    o = gz.pose.orientation
    assert (o.x, o.y, o.z, o.w) == (4.0, 5.0, 6.0, 7.0)
    assert not gz.HasField("header")


def test_spawn_entity_default_relative_to_is_world() -> None:
    request = SpawnEntity.Request()
    request.entity_factory.clone_name = "original"
    gz = spawn_entity_request_to_gz(request)
    assert gz.relative_to == "world"
    assert gz.pose.HasField("orientation")
    assert gz.pose.orientation.w == 1.0


@pytest.mark.parametrize(
    ("fields", "member", "expected"),
    [
        ({"sdf": "s", "sdf_filename": "f", "clone_name": "c"}, "sdf", "s"),
        ({"sdf_filename": "model.sdf", "clone_name": "c"}, "sdf_filename", "model.sdf"),
        ({"clone_name": "existing"}, "clone_name", "existing"),
    ],
)
def test_spawn_entity_source_precedence(fields: dict[str, str], member: str, expected: str) -> None:
    gz = spawn_entity_request_to_gz(spawn_request(**fields))
    assert gz.WhichOneof("from") == member
    assert getattr(gz, member) == expected


def test_spawn_entity_without_source_raises() -> None:
    with pytest.raises(ConversionError, match="sdf, sdf_filename or clone_name"):
        spawn_entity_request_to_gz(spawn_request())


def test_set_entity_pose_request_merges_entity_and_pose() -> None:
    request = SetEntityPose.Request(entity=entity(id_=4_000_000_000, name="box"), pose=pose(-1.0))
    gz = set_entity_pose_request_to_gz(request)
    assert (gz.id, gz.name) == (4_000_000_000, "box")
    assert_vector(gz.position, -1.0, -0.5, -0.75)
    assert (gz.orientation.x, gz.orientation.y, gz.orientation.z, gz.orientation.w) == (
        0.0,
        1.0,
        2.0,
        3.0,
    )
    assert not gz.HasField("header")


def test_set_entity_pose_rejects_an_id_beyond_uint32() -> None:
    request = SetEntityPose.Request(entity=entity(id_=2**32))
    with pytest.raises(ConversionError, match="4294967296"):
        set_entity_pose_request_to_gz(request)


@pytest.mark.parametrize("service", SERVICES, ids=lambda s: s.ros_type)
def test_service_replies_and_failures(service: Any) -> None:
    assert service.gz_rep_type == "gz.msgs.Boolean"
    response_class = service.ros_class.Response
    ok = service.reply_to_ros(GzBoolean(data=True))
    assert isinstance(ok, response_class)
    assert ok.success is True
    assert service.reply_to_ros(GzBoolean(data=False)).success is False
    failure = service.failure_to_ros()
    assert isinstance(failure, response_class)
    assert failure.success is False
    request = service.request_to_gz(_valid_request(service.ros_class))
    assert request.DESCRIPTOR.full_name == service.gz_req_type


def _valid_request(srv_class: Any) -> Any:
    request = srv_class.Request()
    if srv_class is SpawnEntity:
        request.entity_factory.sdf_filename = "model.sdf"
    return request

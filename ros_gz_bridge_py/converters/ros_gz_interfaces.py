"""ros_gz_interfaces: the message pairs (docs/conversions-per-package.md §3.13) and the four bridged
services.

The message conversions are in ``ros_gz_interfaces_messages``, AirSpeed and LogicalCameraImage
in ``ros_gz_interfaces_sensors``. The services (§3.14, plus the
ones ros_gz_bridge 1.0.11+ added) each send one gz request and answer
``success = reply.data``; a failed or timed-out gz request answers ``success = false``.

Differences from ros_gz_bridge:
- SpawnEntity with none of sdf, sdf_filename, clone_name raises ConversionError; the reference
  prints an error and sends an EntityFactory with no source.
- SpawnEntity with more than one source uses the first of sdf, sdf_filename, clone_name
  without printing the reference's warning.
- SetEntityPose with an entity id above 2**32-1 raises ConversionError; the reference
  truncates it into the uint32 gz Pose ``id``, which addresses another entity.
"""

from __future__ import annotations

from typing import Any

from ros_gz_interfaces.msg import (
    AirSpeed,
    Altimeter,
    Contact,
    Contacts,
    Dataframe,
    Entity,
    EntityWrench,
    Float32Array,
    GuiCamera,
    JointWrench,
    Light,
    LogicalCameraImage,
    LogPlaybackStatistics,
    MaterialColor,
    ParamVec,
    SensorNoise,
    StringVec,
    TrackVisual,
    VideoRecord,
    WorldStatistics,
)
from ros_gz_interfaces.srv import ControlWorld, DeleteEntity, SetEntityPose, SpawnEntity

from ros_gz_bridge_py.converters import ros_gz_interfaces_messages as m
from ros_gz_bridge_py.converters import ros_gz_interfaces_sensors as sensors
from ros_gz_bridge_py.converters._fields import fields
from ros_gz_bridge_py.converters.builtin_interfaces import PRESENT_TIME
from ros_gz_bridge_py.converters.geometry_msgs import POSE
from ros_gz_bridge_py.converters.registry import Pair, ServicePair
from ros_gz_bridge_py.errors import ConversionError
from ros_gz_bridge_py.msgs import message_class

_GzWorldControl = message_class("gz.msgs.WorldControl")
_GzEntity = message_class("gz.msgs.Entity")
_GzEntityFactory = message_class("gz.msgs.EntityFactory")
_GzPose = message_class("gz.msgs.Pose")

_UINT32_MAX = (1 << 32) - 1


PAIRS = (
    Pair.of(AirSpeed, "gz.msgs.AirSpeed", sensors.air_speed_to_gz, sensors.air_speed_to_ros),
    Pair.of(Altimeter, "gz.msgs.Altimeter", m.altimeter_to_gz, m.altimeter_to_ros),
    Pair.of(Contact, "gz.msgs.Contact", m.contact_to_gz, m.contact_to_ros),
    Pair.of(Contacts, "gz.msgs.Contacts", m.contacts_to_gz, m.contacts_to_ros),
    Pair.of(Dataframe, "gz.msgs.Dataframe", m.dataframe_to_gz, m.dataframe_to_ros),
    Pair.of(Entity, "gz.msgs.Entity", m.entity_to_gz, m.entity_to_ros),
    Pair.of(EntityWrench, "gz.msgs.EntityWrench", m.entity_wrench_to_gz, m.entity_wrench_to_ros),
    Pair.of(Float32Array, "gz.msgs.Float_V", m.float32_array_to_gz, m.float32_array_to_ros),
    Pair.of(GuiCamera, "gz.msgs.GUICamera", m.gui_camera_to_gz, m.gui_camera_to_ros),
    Pair.of(JointWrench, "gz.msgs.JointWrench", m.joint_wrench_to_gz, m.joint_wrench_to_ros),
    Pair.of(Light, "gz.msgs.Light", m.light_to_gz, m.light_to_ros),
    Pair.of(
        LogicalCameraImage,
        "gz.msgs.LogicalCameraImage",
        sensors.logical_camera_image_to_gz,
        sensors.logical_camera_image_to_ros,
    ),
    Pair.of(
        LogPlaybackStatistics,
        "gz.msgs.LogPlaybackStatistics",
        m.log_playback_statistics_to_gz,
        m.log_playback_statistics_to_ros,
    ),
    Pair.of(
        MaterialColor, "gz.msgs.MaterialColor", m.material_color_to_gz, m.material_color_to_ros
    ),
    Pair.of(ParamVec, "gz.msgs.Param", m.param_vec_to_gz_param, m.param_vec_from_gz_param),
    Pair.of(ParamVec, "gz.msgs.Param_V", m.param_vec_to_gz_param_v, m.param_vec_from_gz_param_v),
    Pair.of(SensorNoise, "gz.msgs.SensorNoise", m.sensor_noise_to_gz, m.sensor_noise_to_ros),
    Pair.of(StringVec, "gz.msgs.StringMsg_V", m.string_vec_to_gz, m.string_vec_to_ros),
    Pair.of(TrackVisual, "gz.msgs.TrackVisual", m.track_visual_to_gz, m.track_visual_to_ros),
    Pair.of(VideoRecord, "gz.msgs.VideoRecord", m.video_record_to_gz, m.video_record_to_ros),
    Pair.of(
        WorldStatistics,
        "gz.msgs.WorldStatistics",
        m.world_statistics_to_gz,
        m.world_statistics_to_ros,
    ),
)


# --- Service requests -----------------------------------------------------------------------


#: WorldControl; ``reset`` and ``run_to_sim_time`` are always present, no header.
_WORLD_CONTROL = fields(
    "pause",
    "step",
    "multi_step",
    ("reset", fields("all", "time_only", "model_only")),
    "seed",
    ("run_to_sim_time", PRESENT_TIME),
)


def control_world_request_to_gz(request: Any) -> Any:
    gz = _GzWorldControl()
    gz.reset.SetInParent()
    _WORLD_CONTROL.to_gz(request.world_control, gz)
    return gz


def delete_entity_request_to_gz(request: Any) -> Any:
    gz = _GzEntity()
    m.ENTITY.to_gz(request.entity, gz)
    return gz


def spawn_entity_request_to_gz(request: Any) -> Any:
    """EntityFactory: the first non-empty of sdf, sdf_filename, clone_name is the source."""
    ros = request.entity_factory
    gz = _GzEntityFactory()
    gz.name = ros.name
    gz.allow_renaming = ros.allow_renaming
    gz.relative_to = ros.relative_to
    if ros.sdf:
        gz.sdf = ros.sdf
    elif ros.sdf_filename:
        gz.sdf_filename = ros.sdf_filename
    elif ros.clone_name:
        gz.clone_name = ros.clone_name
    else:
        msg = (
            "SpawnEntity request: entity_factory needs one of sdf, sdf_filename or clone_name; "
            "all three are empty"
        )
        raise ConversionError(msg)
    POSE.to_gz(ros.pose, gz.pose)
    return gz


def set_entity_pose_request_to_gz(request: Any) -> Any:
    """One gz Pose: ``id`` and ``name`` name the entity, position/orientation the pose."""
    entity = request.entity
    if entity.id > _UINT32_MAX:
        msg = f"SetEntityPose request: entity.id {entity.id} does not fit the uint32 gz Pose id"
        raise ConversionError(msg)
    gz = _GzPose()
    gz.id = entity.id
    gz.name = entity.name
    POSE.to_gz(request.pose, gz)
    return gz


# --- Services -------------------------------------------------------------------------------


def _success_service(srv_class: type[Any], gz_req_type: str, request_to_gz: Any) -> ServicePair:
    """A service whose gz reply is a Boolean and whose ROS response is ``success``."""

    def reply_to_ros(gz_reply: Any) -> Any:
        return srv_class.Response(success=gz_reply.data)

    def failure_to_ros() -> Any:
        return srv_class.Response(success=False)

    package = srv_class.__module__.split(".", 1)[0]
    return ServicePair(
        ros_type=f"{package}/srv/{srv_class.__name__}",
        gz_req_type=gz_req_type,
        gz_rep_type="gz.msgs.Boolean",
        request_to_gz=request_to_gz,
        reply_to_ros=reply_to_ros,
        failure_to_ros=failure_to_ros,
        ros_class=srv_class,
    )


SERVICES = (
    _success_service(ControlWorld, "gz.msgs.WorldControl", control_world_request_to_gz),
    _success_service(DeleteEntity, "gz.msgs.Entity", delete_entity_request_to_gz),
    _success_service(SpawnEntity, "gz.msgs.EntityFactory", spawn_entity_request_to_gz),
    _success_service(SetEntityPose, "gz.msgs.Pose", set_entity_pose_request_to_gz),
)

"""Parameter-defined bridges (bridge_names + bridges.<name>.*), docs/behaviour.md §3.2."""

from __future__ import annotations

from collections.abc import Mapping

import pytest

from ros_gz_bridge_py.config import (
    BridgeSpec,
    Direction,
    ServiceBridgeSpec,
    TopicBridgeSpec,
    parse_parameter_bridges,
)
from ros_gz_bridge_py.errors import ConfigError

_CAMERA = {
    "ros_type_name": "sensor_msgs/msg/Image",
    "ros_topic_name": "camera/image",
    "gz_topic_name": "/world/w/model/cam/image",
    "gz_type_name": "gz.msgs.Image",
}


def _parse(
    bridges: Mapping[str, Mapping[str, object]],
) -> tuple[list[BridgeSpec], list[ConfigError]]:
    def get(key: str) -> object | None:
        prefix, name, field = key.split(".", 2)
        assert prefix == "bridges"
        return bridges[name].get(field)

    result = parse_parameter_bridges(list(bridges), get)
    return list(result.specs), list(result.errors)


def test_topic_bridge_with_defaults() -> None:
    specs, errors = _parse({"cam": _CAMERA})
    assert errors == []
    assert specs == [
        TopicBridgeSpec(
            ros_topic="camera/image",
            gz_topic="/world/w/model/cam/image",
            ros_type="sensor_msgs/msg/Image",
            gz_type="gz.msgs.Image",
            direction=Direction.BIDIRECTIONAL,
            source="parameter bridges.cam",
        )
    ]


def test_topic_bridge_with_every_key() -> None:
    values = {
        **_CAMERA,
        "direction": "GZ_TO_ROS",
        "publisher_queue": 3,
        "subscriber_queue": -1,
        "lazy": True,
        "qos_profile": "SENSOR_DATA",
        "frame_id": "camera_optical",
    }
    (spec,), _ = _parse({"cam": values})
    assert isinstance(spec, TopicBridgeSpec)
    assert spec.direction is Direction.GZ_TO_ROS
    assert (spec.publisher_queue, spec.subscriber_queue, spec.lazy) == (3, None, True)
    assert (spec.qos_profile, spec.frame_id) == ("SENSOR_DATA", "camera_optical")


def test_strings_from_launch_are_accepted() -> None:
    (spec,), _ = _parse({"cam": {**_CAMERA, "lazy": "true", "publisher_queue": "5"}})
    assert isinstance(spec, TopicBridgeSpec)
    assert (spec.lazy, spec.publisher_queue) == (True, 5)


def test_service_bridge() -> None:
    values = {
        "service_name": "/world/default/set_pose",
        "ros_type_name": "ros_gz_interfaces/srv/SetEntityPose",
        "gz_req_type_name": "gz.msgs.Pose",
        "gz_rep_type_name": "gz.msgs.Boolean",
    }
    specs, errors = _parse({"set_pose_bridge": values})
    assert errors == []
    assert specs == [
        ServiceBridgeSpec(
            "/world/default/set_pose",
            "ros_gz_interfaces/srv/SetEntityPose",
            "gz.msgs.Pose",
            "gz.msgs.Boolean",
            "parameter bridges.set_pose_bridge",
        )
    ]


@pytest.mark.parametrize(
    ("values", "message"),
    [
        (
            {k: v for k, v in _CAMERA.items() if k != "ros_type_name"},
            "Bridge b does not set required parameter ros_type_name.",
        ),
        (
            {"ros_type_name": "std_msgs/msg/String"},
            "Bridge b needs to set exactly one of ros_topic_name or service_name.",
        ),
        (
            {**_CAMERA, "service_name": "/s"},
            "Bridge b needs to set exactly one of ros_topic_name or service_name.",
        ),
        (
            {k: v for k, v in _CAMERA.items() if k != "gz_topic_name"},
            "Bridge b does not set required parameter gz_topic_name.",
        ),
        (
            {k: v for k, v in _CAMERA.items() if k != "gz_type_name"},
            "Bridge b does not set required parameter gz_type_name.",
        ),
        (
            {"service_name": "/s", "ros_type_name": "ros_gz_interfaces/srv/DeleteEntity"},
            "Bridge b does not set required parameter gz_req_type_name.",
        ),
        (
            {
                "service_name": "/s",
                "ros_type_name": "ros_gz_interfaces/srv/DeleteEntity",
                "gz_req_type_name": "gz.msgs.Entity",
            },
            "Bridge b does not set required parameter gz_rep_type_name.",
        ),
        ({**_CAMERA, "direction": "UP"}, "Bridge b defines unknown direction UP."),
        ({**_CAMERA, "qos_profile": "FAST"}, "Bridge b defines unknown QoS profile FAST."),
        (
            {**_CAMERA, "publisher_queue": -5},
            "Bridge b has an invalid value: publisher_queue must be a non-negative integer, "
            "got -5; use -1 for the default.",
        ),
        (
            {**_CAMERA, "subscriber_queue": 16777217},
            "Bridge b has an invalid value: subscriber_queue must be at most 16777216, "
            "got 16777217; use -1 for the default.",
        ),
        (
            # rcl reads -p ...:=99999999999999999999 (beyond int64) as a double.
            {**_CAMERA, "publisher_queue": 1e20},
            "Bridge b has an invalid value: publisher_queue must be at most 16777216, "
            "got 1e+20; use -1 for the default.",
        ),
        (
            {**_CAMERA, "lazy": "maybe"},
            "Bridge b has an invalid value: lazy must be true or false, got 'maybe'.",
        ),
        ({**_CAMERA, "frame_id": 7}, "Bridge b sets frame_id to 7; it must be a string."),
    ],
)
def test_invalid_bridges(values: dict[str, object], message: str) -> None:
    specs, errors = _parse({"b": values})
    assert specs == []
    (error,) = errors
    assert (error.message, error.source) == (message, "parameter bridges.b")


def test_invalid_bridge_does_not_stop_the_others() -> None:
    specs, errors = _parse({"bad": {"ros_type_name": "x/msg/Y"}, "cam": _CAMERA})
    assert [spec.source for spec in specs] == ["parameter bridges.cam"]
    assert [error.source for error in errors] == ["parameter bridges.bad"]


def test_direction_none_is_skipped_with_a_warning() -> None:
    result = parse_parameter_bridges(
        ["idle"], lambda key: {**_CAMERA, "direction": "NONE"}.get(key.rsplit(".", 1)[1])
    )
    assert (result.specs, result.errors) == ((), ())
    assert result.warnings == (
        "parameter bridges.idle: direction NONE bridges nothing; the bridge is skipped",
    )


def test_zero_queue_is_kept_with_a_warning() -> None:
    result = parse_parameter_bridges(
        ["cam"], lambda key: {**_CAMERA, "publisher_queue": 0}.get(key.rsplit(".", 1)[1])
    )
    (spec,) = result.specs
    assert isinstance(spec, TopicBridgeSpec)
    assert (spec.publisher_queue, result.errors) == (0, ())
    (warning,) = result.warnings
    assert warning.startswith(
        "parameter bridges.cam: publisher_queue 0 means the middleware's default history depth"
    )

"""vision_msgs Detection2D/3D(Array) <-> gz annotated boxes (docs/conversions-per-package.md
§3.11)."""

from __future__ import annotations

from typing import Any

import pytest
from vision_msgs.msg import (
    Detection2D,
    Detection2DArray,
    Detection3D,
    Detection3DArray,
    ObjectHypothesisWithPose,
)

from ros_gz_bridge_py.converters.vision_msgs import (
    class_id_to_label,
    detection2d_array_to_gz,
    detection2d_array_to_ros,
    detection2d_to_gz,
    detection2d_to_ros,
    detection3d_array_to_gz,
    detection3d_array_to_ros,
    detection3d_to_gz,
    detection3d_to_ros,
)
from ros_gz_bridge_py.errors import ConversionError
from ros_gz_bridge_py.msgs import message_class

Gz2DBox = message_class("gz.msgs.AnnotatedAxisAligned2DBox")
Gz3DBox = message_class("gz.msgs.AnnotatedOriented3DBox")


def hypothesis(class_id: str, score: float = 0.75) -> Any:
    result = ObjectHypothesisWithPose()
    result.hypothesis.class_id = class_id
    result.hypothesis.score = score
    result.pose.pose.position.x = 9.0
    return result


def stamp(ros: Any, sec: int = 2, frame: str = "camera") -> Any:
    ros.header.stamp.sec = sec
    ros.header.stamp.nanosec = 3
    ros.header.frame_id = frame
    return ros


def detection2d(class_id: str = "1") -> Any:
    """The upstream fixture: center (3, 4), size (2, 4)."""
    ros = stamp(Detection2D())
    ros.results = [hypothesis(class_id), hypothesis("5")]
    ros.bbox.center.position.x = 3.0
    ros.bbox.center.position.y = 4.0
    ros.bbox.center.theta = 0.5
    ros.bbox.size_x = 2.0
    ros.bbox.size_y = 4.0
    ros.id = "track-7"
    return ros


def detection3d(class_id: str = "1") -> Any:
    """The upstream fixture: center (2, 4, 6), size (3, 5, 7), a non-unit quaternion."""
    ros = stamp(Detection3D())
    ros.results = [hypothesis(class_id)]
    center = ros.bbox.center
    center.position.x, center.position.y, center.position.z = 2.0, 4.0, 6.0
    o = center.orientation
    o.x, o.y, o.z, o.w = 0.733, 0.462, 0.191, 0.462
    ros.bbox.size.x, ros.bbox.size.y, ros.bbox.size.z = 3.0, 5.0, 7.0
    ros.id = "track-8"
    return ros


def expected_results(label: str) -> list[Any]:
    result = ObjectHypothesisWithPose()
    result.hypothesis.class_id = label
    result.hypothesis.score = 1.0
    return [result]


def test_detection2d_upstream_fixture_to_gz() -> None:
    gz = detection2d_to_gz(detection2d())
    assert (gz.header.stamp.sec, gz.header.stamp.nsec) == (2, 3)
    assert [(d.key, list(d.value)) for d in gz.header.data] == [("frame_id", ["camera"])]
    assert gz.label == 1
    assert (gz.box.min_corner.x, gz.box.min_corner.y) == (2.0, 2.0)
    assert (gz.box.max_corner.x, gz.box.max_corner.y) == (4.0, 6.0)


def test_detection2d_to_ros_keeps_box_label_and_drops_the_rest() -> None:
    ros = detection2d_to_ros(detection2d_to_gz(detection2d("42")))
    assert (ros.header.stamp.sec, ros.header.frame_id) == (2, "camera")
    assert list(ros.results) == expected_results("42")
    assert (ros.bbox.center.position.x, ros.bbox.center.position.y) == (3.0, 4.0)
    assert (ros.bbox.size_x, ros.bbox.size_y) == (2.0, 4.0)
    assert ros.bbox.center.theta == 0.0
    assert ros.id == ""


def test_detection2d_without_results_has_label_zero_and_boxes_present() -> None:
    gz = detection2d_to_gz(Detection2D())
    assert gz.label == 0
    assert gz.HasField("header")
    assert gz.box.HasField("min_corner")
    assert gz.box.HasField("max_corner")
    assert not gz.box.HasField("header")


def test_detection2d_from_absent_box() -> None:
    ros = detection2d_to_ros(Gz2DBox(label=4_000_000_000))
    assert list(ros.results) == expected_results("4000000000")
    assert (ros.bbox.size_x, ros.bbox.size_y) == (0.0, 0.0)


def test_detection2d_array_round_trip() -> None:
    ros = stamp(Detection2DArray(), sec=9, frame="array")
    ros.detections = [detection2d("3"), stamp(detection2d("4"), sec=5, frame="other")]
    gz = detection2d_array_to_gz(ros)
    assert (gz.header.stamp.sec, gz.header.data[0].value[0]) == (9, "array")
    assert [box.label for box in gz.annotated_box] == [3, 4]
    assert gz.annotated_box[1].header.data[0].value[0] == "other"
    back = detection2d_array_to_ros(gz)
    assert (back.header.stamp.sec, back.header.frame_id) == (9, "array")
    assert [d.header.frame_id for d in back.detections] == ["camera", "other"]
    assert [d.results[0].hypothesis.class_id for d in back.detections] == ["3", "4"]
    assert back.detections[1].bbox.size_y == 4.0


def test_detection3d_upstream_fixture_to_gz() -> None:
    gz = detection3d_to_gz(detection3d())
    assert gz.label == 1
    box = gz.box
    assert (box.center.x, box.center.y, box.center.z) == (2.0, 4.0, 6.0)
    assert (box.boxSize.x, box.boxSize.y, box.boxSize.z) == (3.0, 5.0, 7.0)
    o = box.orientation
    assert (o.x, o.y, o.z, o.w) == (0.733, 0.462, 0.191, 0.462)


def test_detection3d_to_ros_keeps_box_and_label() -> None:
    ros = detection3d_to_ros(detection3d_to_gz(detection3d("-1")))
    assert list(ros.results) == expected_results("4294967295")
    center = ros.bbox.center
    assert (center.position.x, center.position.y, center.position.z) == (2.0, 4.0, 6.0)
    o = center.orientation
    assert (o.x, o.y, o.z, o.w) == (0.733, 0.462, 0.191, 0.462)
    assert (ros.bbox.size.x, ros.bbox.size.y, ros.bbox.size.z) == (3.0, 5.0, 7.0)
    assert ros.id == ""


def test_detection3d_default_has_all_box_parts_and_absent_orientation_reads_w0() -> None:
    gz = detection3d_to_gz(Detection3D())
    for part in ("center", "boxSize", "orientation"):
        assert gz.box.HasField(part)
    assert gz.box.orientation.w == 1.0
    assert detection3d_to_ros(Gz3DBox()).bbox.center.orientation.w == 0.0


def test_detection3d_array_round_trip() -> None:
    ros = stamp(Detection3DArray(), sec=11, frame="lidar")
    ros.detections = [detection3d("7"), detection3d("8")]
    gz = detection3d_array_to_gz(ros)
    assert [box.label for box in gz.annotated_box] == [7, 8]
    back = detection3d_array_to_ros(gz)
    assert (back.header.stamp.sec, back.header.frame_id) == (11, "lidar")
    assert [d.results[0].hypothesis.class_id for d in back.detections] == ["7", "8"]
    assert back.detections[0].bbox.size.z == 7.0


@pytest.mark.parametrize(
    ("class_id", "label"),
    [
        ("12", 12),
        ("  \t+7", 7),
        ("12abc", 12),
        ("-1", 2**32 - 1),
        ("2147483647", 2**31 - 1),
        ("-2147483648", 2**31),
        ("007", 7),
    ],
)
def test_class_id_parses_like_stoi(class_id: str, label: int) -> None:
    assert class_id_to_label(class_id) == label


@pytest.mark.parametrize("class_id", ["", "person", " ", "+", "x1", "2147483648", "-2147483649"])
def test_class_id_stoi_rejects_raise_conversion_error(class_id: str) -> None:
    with pytest.raises(ConversionError, match="class_id"):
        detection2d_to_gz(detection2d(class_id))
    with pytest.raises(ConversionError, match="class_id"):
        detection3d_to_gz(detection3d(class_id))

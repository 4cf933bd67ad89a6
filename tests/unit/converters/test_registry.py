"""The registry finds converter modules itself: no list of them to keep up to date."""

from __future__ import annotations

import sys
from collections import defaultdict
from collections.abc import Iterator
from pathlib import Path

import pytest

from ros_gz_bridge_py.converters import registry
from ros_gz_bridge_py.converters.registry import build_registry, modules_of
from ros_gz_bridge_py.errors import UnsupportedTypeError
from ros_gz_bridge_py.msgs.names import canonical_type

CONVERTERS = "ros_gz_bridge_py.converters"

#: Every default that was chosen by module order before the modules were found by name: the
#: default Gazebo type of each ROS type with several, and the default ROS type of each Gazebo
#: type with several.
GZ_DEFAULTS = {
    "nav_msgs/msg/Odometry": "gz.msgs.Odometry",
    "sensor_msgs/msg/Imu": "gz.msgs.IMU",
    "sensor_msgs/msg/NavSatFix": "gz.msgs.NavSat",
    "ros_gz_interfaces/msg/ParamVec": "gz.msgs.Param",
}
ROS_DEFAULTS = {
    "gz.msgs.Vector3d": "geometry_msgs/msg/Point",
    "gz.msgs.Pose": "geometry_msgs/msg/Pose",
    "gz.msgs.Pose_V": "geometry_msgs/msg/PoseArray",
    "gz.msgs.PoseWithCovariance": "geometry_msgs/msg/PoseWithCovariance",
    "gz.msgs.Twist": "geometry_msgs/msg/Twist",
    "gz.msgs.TwistWithCovariance": "geometry_msgs/msg/TwistWithCovariance",
    "gz.msgs.Wrench": "geometry_msgs/msg/Wrench",
    "gz.msgs.LaserScan": "sensor_msgs/msg/LaserScan",
    "gz.msgs.NavSat": "sensor_msgs/msg/NavSatFix",
}


@pytest.fixture
def fake_package(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Iterator[str]:
    """A package with a converter module, a helper without pairs, and one that cannot load."""
    package = tmp_path / "fake_converters"
    package.mkdir()
    (package / "__init__.py").write_text("")
    (package / "b_msgs.py").write_text(
        "from std_msgs.msg import Bool\n"
        "from ros_gz_bridge_py.converters.registry import Pair\n"
        "from fake_converters.b_msgs_helper import identity\n"
        'PAIRS = (Pair("b_msgs/msg/Bool", "gz.msgs.Boolean", identity, identity, Bool),)\n'
    )
    (package / "b_msgs_helper.py").write_text("def identity(message):\n    return message\n")
    (package / "a_msgs.py").write_text("import no_such_interface_package.msg\nPAIRS = ()\n")
    (package / "_private.py").write_text("raise AssertionError('private modules are not read')\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    yield "fake_converters"
    for name in [name for name in sys.modules if name.startswith("fake_converters")]:
        del sys.modules[name]


def test_modules_of_lists_public_modules_by_name(fake_package: str) -> None:
    assert [name for name, _ in modules_of(fake_package)] == ["a_msgs", "b_msgs", "b_msgs_helper"]


def test_a_module_with_pairs_is_found_a_helper_ignored_a_missing_package_recorded(
    fake_package: str,
) -> None:
    found = build_registry(modules_of(fake_package))
    assert [(p.ros_type, p.gz_type, p.origin) for p in found.pairs] == [
        ("b_msgs/msg/Bool", "gz.msgs.Boolean", "b_msgs")
    ]
    assert list(found.unavailable) == ["a_msgs"]
    assert "no_such_interface_package" in found.unavailable["a_msgs"]


def test_every_converter_module_of_the_package_is_found() -> None:
    names = [name for name, _ in modules_of(CONVERTERS)]
    found = build_registry(modules_of(CONVERTERS))
    origins = {p.origin for p in found.pairs} | {s.origin for s in found.services}
    assert not found.unavailable
    assert origins == {
        "actuator_msgs",
        "builtin_interfaces",
        "geometry_msgs",
        "gps_msgs",
        "marine_acoustic_msgs",
        "nav_msgs",
        "rcl_interfaces",
        "ros_gz_interfaces",
        "rosgraph_msgs",
        "sensor_msgs",
        "std_msgs",
        "tf2_msgs",
        "trajectory_msgs",
        "vision_msgs",
    }
    # Helpers are read too, and add nothing.
    assert {"ros_gz_interfaces_messages", "sensor_msgs_image", "registry"} <= set(names)


def test_modules_are_listed_in_name_order() -> None:
    origins = [p.origin for p in build_registry(modules_of(CONVERTERS)).pairs]
    first_seen = list(dict.fromkeys(origins))
    assert first_seen == sorted(first_seen)


def test_defaults_are_those_chosen_before_discovery() -> None:
    found = registry.default_registry()
    for ros_type, gz_type in GZ_DEFAULTS.items():
        assert found.gz_types_for(ros_type)[0] == gz_type, ros_type
    for gz_type, ros_type in ROS_DEFAULTS.items():
        assert found.ros_types_for(gz_type)[0] == ros_type, gz_type
    several_gz = {p.ros_type for p in found.pairs if len(found.gz_types_for(p.ros_type)) > 1}
    several_ros = {p.gz_type for p in found.pairs if len(found.ros_types_for(p.gz_type)) > 1}
    assert several_gz == set(GZ_DEFAULTS)
    assert several_ros == set(ROS_DEFAULTS)


def test_a_gazebo_type_paired_by_several_modules_marks_its_default() -> None:
    """Else the default would be whichever module's name sorts first."""
    origins: dict[str, set[str]] = defaultdict(set)
    marked: dict[str, list[str]] = defaultdict(list)
    for pair in build_registry(modules_of(CONVERTERS)).pairs:
        origins[canonical_type(pair.gz_type)].add(pair.origin)
        if pair.default_for_gz_type:
            marked[canonical_type(pair.gz_type)].append(pair.ros_type)
    shared = {gz_type for gz_type, modules in origins.items() if len(modules) > 1}
    assert shared == set(marked)
    assert all(len(ros_types) == 1 for ros_types in marked.values())


def test_a_missing_interface_package_is_recorded_and_the_rest_keeps_working(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    monkeypatch.setitem(sys.modules, "gps_msgs.msg", None)
    monkeypatch.delitem(sys.modules, f"{CONVERTERS}.gps_msgs")
    found = build_registry(modules_of(CONVERTERS))
    assert list(found.unavailable) == ["gps_msgs"]
    assert "gps_msgs.msg" in found.unavailable["gps_msgs"]
    assert found.ros_types_for("gz.msgs.NavSat") == ["sensor_msgs/msg/NavSatFix"]
    with pytest.raises(UnsupportedTypeError, match="converters for gps_msgs could not load"):
        found.get("gps_msgs/msg/GPSFix", "gz.msgs.NavSat")

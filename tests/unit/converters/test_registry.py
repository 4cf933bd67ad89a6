"""The registry finds converter modules itself: no list of them to keep up to date."""

from __future__ import annotations

import importlib
import re
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
    assert found.unavailable["gps_msgs"] == (
        "the ROS interface package gps_msgs is not installed; build it with "
        "`tools/setup_interfaces.sh <venv> gps_msgs` from the source tree (`make setup` builds "
        "them all), or install ros-jazzy-gps-msgs in a ROS install"
    )
    assert found.ros_types_for("gz.msgs.NavSat") == ["sensor_msgs/msg/NavSatFix"]
    with pytest.raises(UnsupportedTypeError, match="converters for gps_msgs could not load"):
        found.get("gps_msgs/msg/GPSFix", "gz.msgs.NavSat")


def test_a_missing_package_is_named_by_each_of_its_modules_and_by_its_services(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """ros_gz_interfaces has three converter modules; a service entry of it said "supported:
    none" where a topic entry named the package and the command that builds it."""
    modules = ["ros_gz_interfaces", "ros_gz_interfaces_messages", "ros_gz_interfaces_sensors"]
    for module in modules:
        monkeypatch.delitem(sys.modules, f"{CONVERTERS}.{module}", raising=False)
    monkeypatch.setitem(sys.modules, "ros_gz_interfaces.msg", None)
    monkeypatch.setitem(sys.modules, "ros_gz_interfaces.srv", None)
    found = build_registry(modules_of(CONVERTERS))
    assert sorted(found.unavailable) == modules
    missing = "the ROS interface package ros_gz_interfaces is not installed; build it with "
    assert all(reason.startswith(missing) for reason in found.unavailable.values())
    with pytest.raises(
        UnsupportedTypeError,
        match=r"service type \[ros_gz_interfaces/srv/ControlWorld\] is not supported here: "
        f"converters for ros_gz_interfaces could not load: {missing}",
    ):
        found.get_service("ros_gz_interfaces/srv/ControlWorld")


def test_other_import_failures_are_recorded_as_they_were_raised() -> None:
    inner = ModuleNotFoundError("No module named 'numpy'", name="numpy")
    assert registry.why_unavailable("gps_msgs", inner) == "No module named 'numpy'"
    pypi = ModuleNotFoundError("No module named 'nav_msgs'", name="nav_msgs")
    assert registry.why_unavailable("nav_msgs", pypi) == "No module named 'nav_msgs'"


def test_the_packages_built_from_source_are_those_the_set_up_builds() -> None:
    script = (Path(__file__).parents[3] / "tools" / "setup_interfaces.sh").read_text()
    listed = re.search(r"^DEFAULT_PACKAGES=\((.*)\)$", script, re.MULTILINE)
    assert listed is not None
    assert set(listed.group(1).split()) == registry.BUILT_FROM_SOURCE


def test_every_pair_is_in_the_module_of_its_ros_package() -> None:
    """What lets a lookup import only the module of the type's package (``lazy_registry``)."""
    found = build_registry(modules_of(CONVERTERS))
    declared = [(p.ros_type, p.origin) for p in found.pairs]
    declared += [(s.ros_type, s.origin) for s in found.services]
    for ros_type, origin in declared:
        assert ros_type.partition("/")[0] == origin, ros_type


def test_a_lookup_imports_only_its_package_module(fake_package: str) -> None:
    folder = Path(importlib.import_module(fake_package).__path__[0])
    (folder / "c_msgs.py").write_text("PAIRS = ()\n")
    lazy = registry.lazy_registry(modules_of(fake_package))
    assert lazy.find("b_msgs/msg/Bool", "gz.msgs.Boolean") is not None
    assert f"{fake_package}.c_msgs" not in sys.modules
    assert lazy.find("b_msgs/msg/Bool", "gz.msgs.Nothing") is None  # a miss reads them all
    assert list(lazy.unavailable) == ["a_msgs"]


def test_a_lazy_registry_answers_as_one_that_imported_everything() -> None:
    full = build_registry(modules_of(CONVERTERS))
    lazy = registry.lazy_registry(modules_of(CONVERTERS))
    for pair in full.pairs:
        assert lazy.find(pair.ros_type, pair.gz_type) == pair
    for service in full.services:
        assert lazy.get_service(service.ros_type) == service
    assert lazy.pairs == full.pairs
    assert lazy.services == full.services
    for pair in full.pairs:
        assert lazy.ros_types_for(pair.gz_type) == full.ros_types_for(pair.gz_type)
        assert lazy.gz_types_for(pair.ros_type) == full.gz_types_for(pair.ros_type)


def test_listing_a_lazy_registry_keeps_the_reading_order() -> None:
    """Pairs imported by a lookup first are still listed where their module's name puts them."""
    lazy = registry.lazy_registry(modules_of(CONVERTERS))
    lazy.get("vision_msgs/msg/Detection2D", "gz.msgs.AnnotatedAxisAligned2DBox")
    origins = [p.origin for p in lazy.pairs]
    assert list(dict.fromkeys(origins)) == sorted(set(origins))

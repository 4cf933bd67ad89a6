"""Third-party converters are found through the real entry-point mechanism, without pip.

A ``*.dist-info`` directory with ``METADATA`` and ``entry_points.txt`` is written next to the
example plugin's source on ``sys.path``; ``importlib.metadata`` then sees it as installed.
"""

from __future__ import annotations

from pathlib import Path

import pytest
from std_msgs.msg import UInt8MultiArray

from ros_gz_bridge_py.app import bridge_types
from ros_gz_bridge_py.converters import registry
from ros_gz_bridge_py.msgs import message_class

EXAMPLE = Path(__file__).resolve().parents[3] / "examples" / "converter_plugin"


@pytest.fixture
def installed_plugin(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    dist_info = tmp_path / "ros_gz_bytes_plugin-0.1.0.dist-info"
    dist_info.mkdir()
    (dist_info / "METADATA").write_text(
        "Metadata-Version: 2.1\nName: ros_gz_bytes_plugin\nVersion: 0.1.0\n"
    )
    (dist_info / "entry_points.txt").write_text(
        f"[{registry.ENTRY_POINT_GROUP}]\nros_gz_bytes_plugin = ros_gz_bytes_plugin\n"
    )
    monkeypatch.syspath_prepend(str(EXAMPLE))
    monkeypatch.syspath_prepend(str(tmp_path))


@pytest.mark.usefixtures("installed_plugin")
def test_registry_finds_and_converts_the_plugin_pair() -> None:
    pair = registry.build_registry().get("std_msgs/msg/UInt8MultiArray", "ignition.msgs.Bytes")
    assert pair.origin == "ros_gz_bytes_plugin"
    gz = pair.to_gz(UInt8MultiArray(data=b"\x00\x01\xff"))
    assert gz.DESCRIPTOR.full_name == "gz.msgs.Bytes"
    assert gz.data == b"\x00\x01\xff"
    wire = gz.SerializeToString()
    back = pair.to_ros(message_class("gz.msgs.Bytes").FromString(wire))
    assert bytes(back.data) == b"\x00\x01\xff"


@pytest.mark.usefixtures("installed_plugin")
def test_bridge_types_lists_the_plugin_pair(capsys: pytest.CaptureFixture[str]) -> None:
    assert bridge_types.main(["--print-pairs"]) == 0
    out = capsys.readouterr().out
    assert "  - 'std_msgs/msg/UInt8MultiArray' (ROS) <=> 'gz.msgs.Bytes' (GZ)" in out.splitlines()


def test_without_the_plugin_the_pair_is_absent() -> None:
    assert registry.build_registry().find("std_msgs/msg/UInt8MultiArray", "gz.msgs.Bytes") is None


@pytest.mark.usefixtures("installed_plugin")
def test_a_lazy_registry_finds_the_plugin_pair_of_a_package_it_has_a_module_for() -> None:
    pair = registry.lazy_registry().get("std_msgs/msg/UInt8MultiArray", "gz.msgs.Bytes")
    assert pair.origin == "ros_gz_bytes_plugin"

"""Our gz.msgs schemas against Debian's real Fortress (ign-msgs 8) ``.proto`` files.

The Fortress files are compiled with protoc and compared with our committed descriptor set
(whose freshness tests/unit/msgs/test_pool.py checks): for every message we define that also exists
in ign-msgs 8, each field both define must have the same number, name and wire type, and each
enum value both define the same name. Additive fields (docs/protocol-lines.md §9.5) are only on one
side, so they are not compared. ``gz.msgs.IMU`` is the one known renumbering: it is skipped, and our
``ignition.msgs.IMU`` is compared with the Fortress IMU instead.
"""

from __future__ import annotations

import os
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
from google.protobuf import descriptor_pb2

from ros_gz_bridge_py.msgs import regen
from ros_gz_bridge_py.msgs.names import Spelling, respell

pytestmark = pytest.mark.peer

FORTRESS_ROOT = Path("/usr/include/ignition/msgs8")
FORTRESS_DIR = FORTRESS_ROOT / "ignition" / "msgs"

_FDP = descriptor_pb2.FieldDescriptorProto
_VARINT = {
    _FDP.TYPE_INT32, _FDP.TYPE_INT64, _FDP.TYPE_UINT32, _FDP.TYPE_UINT64, _FDP.TYPE_SINT32,
    _FDP.TYPE_SINT64, _FDP.TYPE_BOOL, _FDP.TYPE_ENUM,
}  # fmt: skip
_FIXED64 = {_FDP.TYPE_DOUBLE, _FDP.TYPE_FIXED64, _FDP.TYPE_SFIXED64}
_FIXED32 = {_FDP.TYPE_FLOAT, _FDP.TYPE_FIXED32, _FDP.TYPE_SFIXED32}


def _wire_type(field: Any) -> int:
    """Protobuf wire type a proto3 field is written with (repeated scalars are packed)."""
    scalar = field.type in _VARINT | _FIXED64 | _FIXED32
    packed = field.options.packed if field.options.HasField("packed") else True
    if field.label == _FDP.LABEL_REPEATED and scalar and packed:
        return 2
    if field.type in _VARINT:
        return 0
    if field.type in _FIXED64:
        return 1
    if field.type in _FIXED32:
        return 5
    return 2


def _local_name(full_name: str) -> str:
    """``.gz.msgs.Header.Map`` / ``ignition.msgs.Header.Map`` -> ``Header.Map``."""
    for prefix in (".", "gz.msgs.", "ignition.msgs."):
        full_name = full_name.removeprefix(prefix)
    return full_name


def _walk(file_set: Any) -> Iterator[tuple[str, Any, str]]:
    """(full name, descriptor proto, kind) of every message and enum, nested ones included."""

    def nested(prefix: str, message: Any) -> Iterator[tuple[str, Any, str]]:
        name = f"{prefix}.{message.name}"
        yield name, message, "message"
        for enum in message.enum_type:
            yield f"{name}.{enum.name}", enum, "enum"
        for inner in message.nested_type:
            yield from nested(name, inner)

    for file_proto in file_set.file:
        for enum in file_proto.enum_type:
            yield f"{file_proto.package}.{enum.name}", enum, "enum"
        for message in file_proto.message_type:
            yield from nested(file_proto.package, message)


@pytest.fixture(scope="module")
def fortress(tmp_path_factory: pytest.TempPathFactory) -> dict[str, tuple[Any, str]]:
    if not FORTRESS_DIR.is_dir():
        if os.environ.get("CI"):
            pytest.fail(f"{FORTRESS_DIR} is missing in CI: install libignition-msgs-dev")
        pytest.skip(f"{FORTRESS_DIR} not installed")
    output = tmp_path_factory.mktemp("fortress") / "fortress.desc"
    files = regen.proto_files(FORTRESS_ROOT)
    regen.build_descriptor_set(FORTRESS_ROOT, files, output)
    file_set = descriptor_pb2.FileDescriptorSet.FromString(output.read_bytes())
    return {name: (proto, kind) for name, proto, kind in _walk(file_set)}


def _ours() -> dict[str, tuple[Any, str]]:
    data = regen.DESCRIPTOR_SET.read_bytes()
    file_set = descriptor_pb2.FileDescriptorSet.FromString(data)
    return {name: (proto, kind) for name, proto, kind in _walk(file_set)}


OURS = _ours()
# gz.msgs.IMU is renumbered since Fortress; ignition.msgs.IMU stands for the Fortress layout.
SKIPPED = {"gz.msgs.IMU"}
# Top-level types added after Fortress (docs/protocol-lines.md §9.5); their nested types go with
# them. NavSatWithCovariance is newer still (Jetty).
HARMONIC_ONLY = {
    "gz.msgs.Dataframe", "gz.msgs.EntityWrench", "gz.msgs.MaterialColor",
    "gz.msgs.OdometryWithCovariance", "gz.msgs.PoseWithCovariance",
    "gz.msgs.TwistWithCovariance", "gz.msgs.SphericalCoordinatesType",
    "gz.msgs.AirSpeed", "gz.msgs.DVLBeamState", "gz.msgs.DVLKinematicEstimate",
    "gz.msgs.DVLRangeEstimate", "gz.msgs.DVLTrackingTarget", "gz.msgs.DVLVelocityTracking",
    "gz.msgs.NavSatWithCovariance",
}  # fmt: skip
COMPARED = sorted(
    name
    for name in OURS
    if name not in SKIPPED and ".".join(name.split(".")[:3]) not in HARMONIC_ONLY
)


def _fortress_name(ours: str) -> str:
    return respell(ours, Spelling.IGNITION)


def test_harmonic_only_types_are_absent_from_fortress(
    fortress: dict[str, tuple[Any, str]],
) -> None:
    assert OURS.keys() >= HARMONIC_ONLY
    assert not {_fortress_name(name) for name in HARMONIC_ONLY} & fortress.keys()


@pytest.mark.parametrize("name", COMPARED)
def test_fields_and_enum_values_match_fortress(
    name: str, fortress: dict[str, tuple[Any, str]]
) -> None:
    theirs = fortress[_fortress_name(name)]
    ours, kind = OURS[name]
    assert theirs[1] == kind
    if kind == "enum":
        our_values = {v.number: v.name for v in ours.value}
        their_values = {v.number: v.name for v in theirs[0].value}
        common = our_values.keys() & their_values.keys()
        assert common
        assert {n: our_values[n] for n in common} == {n: their_values[n] for n in common}
        return
    _assert_same_wire_fields(name, ours, theirs[0])


def _assert_same_wire_fields(name: str, ours: Any, theirs: Any) -> None:
    """Fields both define (by name or by number) agree on number, name and wire shape."""
    our_names = {f.name: f for f in ours.field}
    their_names = {f.name: f for f in theirs.field}
    their_numbers = {f.number: f.name for f in theirs.field}
    for field_name in our_names.keys() & their_names.keys():
        mine, real = our_names[field_name], their_names[field_name]
        assert (mine.number, _wire_type(mine), mine.label) == (
            real.number,
            _wire_type(real),
            real.label,
        ), f"{name}.{field_name}"
        assert _local_name(mine.type_name) == _local_name(real.type_name), f"{name}.{field_name}"
    for field in ours.field:
        assert their_numbers.get(field.number, field.name) == field.name, (
            f"{name} field {field.number}"
        )

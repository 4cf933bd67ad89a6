"""The numbers of native/codes.py: the protobuf ones are protobuf's, and codes.h (what the C
files read) holds every one under its C name."""

from __future__ import annotations

from google.protobuf.descriptor import FieldDescriptor

from ros_gz_bridge_py.native.codes import C_PREFIXES, Op, PbType, c_header


def test_protobuf_types_are_numbered_as_protobuf_numbers_them() -> None:
    for member in PbType:
        assert getattr(FieldDescriptor, f"TYPE_{member.name}") == member


def test_the_c_header_names_every_code_and_counts_those_from_zero() -> None:
    header = c_header()
    for codes, prefix in C_PREFIXES.items():
        for code in codes:
            assert f"    {prefix}{code.name} = {code.value},\n" in header
    assert f"    OP_COUNT = {len(Op)},\n" in header
    assert "PB_COUNT" not in header

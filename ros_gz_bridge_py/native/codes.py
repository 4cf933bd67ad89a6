"""The numbers the compilers (``program.py``, ``encoder.py``) write into programs and the C
transcoders read back, declared once: the C files see them in ``codes.h``, which
:func:`write_c_header` writes from this module when the extension or a fuzz target is built
(``setup.py``, ``tools/native_fuzz_programs.py``). Each enumeration is numbered in the order
of its names; in C its members are ``PREFIX_NAME``. No import of the package: setup.py loads
this file alone, before the package can be imported.
"""

from __future__ import annotations

from enum import IntEnum
from pathlib import Path

#: Ops of a Gazebo -> ROS program (transcode.c; docs/native.md §3).
Op = IntEnum(
    "Op",
    "END NUM CONST STR CONST_STR HEADER_STR FIXED_LIST SEQ_MSG COLUMN COLUMN_STR CLOCK "
    "CONST_BLOCK WALL_STAMP",
    start=0,
)
#: Read ops (the CDR message into slots) and write ops (the protobuf payload from them) of a
#: ROS -> Gazebo encoder (encode.c, encode_write.c; docs/native.md §6).
ReadOp = IntEnum("ReadOp", "END NUM STR ARR SEQ_NUM SEQ_STR SEQ_MSG", start=0)
WriteOp = IntEnum("WriteOp", "END NUM STR STR_REP CONST_STR MSG SEQ_MSG PACKED SEQ_STR", start=0)
#: Protobuf field types, as google.protobuf.FieldDescriptor.TYPE_* numbers them.
PbType = IntEnum(
    "PbType",
    "DOUBLE FLOAT INT64 UINT64 INT32 FIXED64 FIXED32 BOOL STRING GROUP MESSAGE BYTES UINT32 "
    "ENUM SFIXED32 SFIXED64 SINT32 SINT64",
)
#: ROS basic types as the programs number them (``octet`` is a ``uint8``).
RosKind = IntEnum(
    "RosKind", "BOOLEAN UINT8 INT8 INT16 UINT16 INT32 UINT32 INT64 UINT64 FLOAT DOUBLE"
)
#: How a number changes type: exactly (out of range: Python decides), or narrowed as C++ does.
Conv = IntEnum("Conv", "EXACT WRAP", start=0)

#: Each enumeration's prefix in C.
C_PREFIXES: dict[type[IntEnum], str] = {
    Op: "OP_", ReadOp: "R_", WriteOp: "W_", PbType: "PB_", RosKind: "ROS_", Conv: "CONV_",
}  # fmt: skip


def c_header() -> str:
    """The text of codes.h: a C enum per enumeration; one numbered from 0 also gets
    ``PREFIX_COUNT``, its number of members (the size of a table indexed by them)."""
    lines = ["/* Generated from codes.py (the numbers' one declaration) at build time. */",
             "#ifndef RGB_CODES_H", "#define RGB_CODES_H"]  # fmt: skip
    for codes, prefix in C_PREFIXES.items():
        members = [f"{prefix}{code.name} = {code.value}" for code in codes]
        if min(codes) == 0:
            members.append(f"{prefix}COUNT = {len(codes)}")
        lines += ["enum {", *(f"    {member}," for member in members), "};"]
    return "\n".join([*lines, "#endif", ""])


def write_c_header(path: Path) -> None:
    """Writes codes.h at ``path``, unless it holds that text already (its time then stays,
    and so does what was compiled from it)."""
    text = c_header()
    if not path.exists() or path.read_text() != text:
        path.write_text(text)

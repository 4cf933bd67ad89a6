"""Write the inputs of the native transcoders' fuzz targets (fuzz/transcode_fuzz.c,
fuzz/encode_fuzz.c).

Usage::

    python -m tools.native_fuzz_programs OUT_DIR [--target encode]

writes ``OUT_DIR/programs.h``, the words of every pair whose program compiles
(``compile_to_ros``) as C arrays, ``OUT_DIR/codes.h`` (the numbers the C files read,
``native/codes.py``), and ``OUT_DIR/corpus/``, the seed inputs: per program, its
index byte then a valid payload (empty, a message with every field set, :func:`distinctive`,
and the same shaped to cost: wrapped in small unknown fields, or followed by thousands of
empty elements); and one seed of each program-loading mode (the fuzz target's comment
says how an input is read). With ``--target encode``, the same for the ROS -> Gazebo encoders
(``compile_to_gz``): ``OUT_DIR/encoders.h``, and seeds of CDR messages (the default message,
and one with every field set, :func:`distinctive_ros`). With ``--target loop``, programs.h and
seeds of fuzz/loop_fuzz.c: per program, a channel's first messages (handed back, judged,
then taken natively), and scripts of the queue's bounds, a failing publisher, a flood of
senders and a topic the channel's own prefixes. All are build products under ``.build/``, never
committed.
"""

from __future__ import annotations

import argparse
import itertools
import struct
from collections.abc import Iterator, Sequence
from pathlib import Path
from typing import Any

from ros_gz_bridge_py.converters.registry import Pair, default_registry
from ros_gz_bridge_py.msgs import message_class
from ros_gz_bridge_py.native.codes import Conv, PbType, ReadOp, RosKind, WriteOp, write_c_header
from ros_gz_bridge_py.native.encoder import compile_to_gz
from ros_gz_bridge_py.native.program import Compiled, compile_to_ros
from ros_gz_bridge_py.native.words import NotExpressibleError
from ros_gz_bridge_py.ros import cdr_types as cdr

#: The fuzz targets' modes, by the first input byte (fuzz/transcode_fuzz.c, fuzz/encode_fuzz.c).
LOAD_MODE, MUTATE_MODE = 0x80, 0xC0
_HEADER_TYPES = {"gz.msgs.Header", "ignition.msgs.Header"}
_WIDE = {PbType.INT64, PbType.UINT64, PbType.FIXED64, PbType.SFIXED64, PbType.SINT64}


def compiled_pairs() -> list[tuple[Pair, Compiled]]:
    """Every pair of the default registry whose program compiles, in registry order."""
    found = []
    for pair in default_registry().pairs:
        try:
            found.append((pair, compile_to_ros(pair)))
        except NotExpressibleError:
            continue
    return found


def compiled_encoders() -> list[tuple[Pair, bytes]]:
    """Every pair of the default registry whose encoder compiles, in registry order."""
    found = []
    for pair in default_registry().pairs:
        try:
            found.append((pair, compile_to_gz(pair)))
        except NotExpressibleError:
            continue
    return found


def _scalar(field: Any, n: int) -> Any:
    """A positive value of ``field``'s type that no other field given another ``n`` has (n >= 1;
    a 64-bit one narrows to the same positive int32, or Clock would refuse the message)."""
    kind = field.type
    if kind == PbType.DOUBLE:
        return n * 1.5 + 0.25
    if kind == PbType.FLOAT:
        return n + 0.5
    if kind == PbType.BOOL:
        return True
    if kind == PbType.STRING:
        return f"s{n}::part::{n}é"
    if kind == PbType.BYTES:
        return bytes([n % 256, 0, 255])
    if kind == PbType.ENUM:
        numbers = [value.number for value in field.enum_type.values if value.number != 0]
        return numbers[n % len(numbers)] if numbers else n
    value = n * 7 + 3
    return (value << 32) + value if kind in _WIDE else value


def _header(header: Any, counter: Iterator[int], ancestors: frozenset[str]) -> None:
    """A gz Header whose ``data`` tries the converters' rules: entries without a value, the
    first ``child_frame_id`` and the last ``frame_id`` that have one, a key nobody reads."""
    fill(header.stamp, counter, ancestors)
    n = next(counter)
    entries = [
        ("frame_id", [f"world::early{n}", "unused"]),
        ("child_frame_id", [f"robot::base{n}é", "unused"]),
        ("frame_id", []),
        ("other", [f"other{n}"]),
        ("frame_id", [f"world::model::link{n}é"]),
        ("child_frame_id", [f"late_child{n}"]),
        ("child_frame_id", []),
    ]
    for key, values in entries:
        entry = header.data.add()
        entry.key = key
        entry.value.extend(values)


def fill(msg: Any, counter: Iterator[int], ancestors: frozenset[str] = frozenset()) -> Any:
    """Sets every field of ``msg`` (counter values, several elements per repeated field) and
    returns it; a message type already being filled further up is left empty (recursion)."""
    name = msg.DESCRIPTOR.full_name
    if name in _HEADER_TYPES:
        _header(msg, counter, ancestors | {name})
        return msg
    inner = ancestors | {name}
    for field in msg.DESCRIPTOR.fields:
        count = (3 if len(ancestors) < 3 else 1) if field.is_repeated else 1
        if field.message_type is not None:
            if field.message_type.full_name in inner:
                continue
            for _ in range(count):
                sub = (
                    getattr(msg, field.name).add()
                    if field.is_repeated
                    else getattr(msg, field.name)
                )
                sub.SetInParent()
                fill(sub, counter, inner)
        elif field.is_repeated:
            getattr(msg, field.name).extend(_scalar(field, next(counter)) for _ in range(count))
        else:
            setattr(msg, field.name, _scalar(field, next(counter)))
    return msg


def distinctive(gz_type: str) -> Any:
    """A ``gz_type`` message with every field set to a value no other field has."""
    return fill(message_class(gz_type)(), itertools.count(1))


#: Bits of the ROS integer types, and whether they are signed.
_ROS_INTEGERS = {
    "int8": (8, True), "uint8": (8, False), "int16": (16, True), "uint16": (16, False),
    "int32": (32, True), "uint32": (32, False), "int64": (64, True), "uint64": (64, False),
}  # fmt: skip


def _ros_scalar(basic: str, n: int) -> Any:
    """A positive value of ROS type ``basic`` that few other fields given another ``n`` have
    (small enough for every Gazebo field a converter assigns it to)."""
    if basic in ("float", "double"):
        return n + 0.5
    if basic == "boolean":
        return True
    bits, signed = _ROS_INTEGERS[basic]
    return (n * 7 + 3) % 2 ** (bits - signed) or 1


def fill_ros(msg: Any, counter: Iterator[int], depth: int = 0) -> Any:
    """Sets every field of the ROS ``msg`` (counter values, several elements per sequence;
    ``char`` and ``octet`` fields, which no encoder reads, keep their default) and returns it."""
    for name, rosidl in cdr.fields_of(type(msg)):
        kind, basic = type(rosidl).__name__, cdr.basic_of(rosidl)
        element = getattr(rosidl, "value_type", None)
        element_basic = cdr.basic_of(element)
        if basic in ("char", "octet") or element_basic in ("char", "octet"):
            continue
        if basic is not None:
            setattr(msg, name, _ros_scalar(basic, next(counter)))
        elif kind in cdr.STRING_TYPES:
            setattr(msg, name, f"s{next(counter)}::part::é")
        elif kind == "NamespacedType":
            fill_ros(getattr(msg, name), counter, depth + 1)
        elif kind == "Array" and element_basic is not None:
            values = [_ros_scalar(element_basic, next(counter)) for _ in range(rosidl.size)]
            setattr(msg, name, values)
        elif kind in cdr.SEQUENCE_TYPES:
            setattr(msg, name, _ros_items(element, counter, 3 if depth < 2 else 1, depth))
    return msg


def _ros_items(element: Any, counter: Iterator[int], count: int, depth: int) -> list[Any]:
    basic = cdr.basic_of(element)
    if basic is not None:
        return [_ros_scalar(basic, next(counter)) for _ in range(count)]
    if type(element).__name__ in cdr.STRING_TYPES:
        return [f"s{next(counter)}é" for _ in range(count)]
    cls = cdr.nested_class(element)
    return [fill_ros(cls(), counter, depth + 1) for _ in range(count)]


def distinctive_ros(ros_class: type[Any]) -> Any:
    """A ``ros_class`` message with every field set to a value few other fields have."""
    return fill_ros(ros_class(), itertools.count(1))


def _words(name: str, data: bytes) -> str:
    values = struct.unpack(f"<{len(data) // 4}i", data)
    return f"static const int32_t {name}[] = {{{', '.join(map(str, values))}}};\n"


def header_text(programs: Sequence[tuple[Pair, Compiled]]) -> str:
    """The C header: one schema and one ops array per program, and the table of them."""
    lines = ["/* Generated by tools/native_fuzz_programs.py: do not edit, do not commit. */\n"]
    lines.append("#include <stddef.h>\n#include <stdint.h>\n\n")
    for i, (_pair, compiled) in enumerate(programs):
        lines.append(_words(f"schema_{i}", compiled.schema))
        lines.append(_words(f"ops_{i}", compiled.ops))
    lines.append("\nstruct fuzz_program {\n    const char *name;\n")
    lines.append("    const int32_t *schema;\n    size_t schema_len;\n")
    lines.append("    const int32_t *ops;\n    size_t ops_len;\n};\n\n")
    lines.append("static const struct fuzz_program PROGRAMS[] = {\n")
    for i, (pair, compiled) in enumerate(programs):
        lines.append(
            f'    {{"{pair.ros_type} <- {pair.gz_type}", schema_{i}, '
            f"{len(compiled.schema) // 4}, ops_{i}, {len(compiled.ops) // 4}}},\n"
        )
    lines.append("};\n")
    lines.append(f"#define PROGRAM_COUNT {len(programs)}\n")
    return "".join(lines)


def seeds(programs: Sequence[tuple[Pair, Compiled]]) -> dict[str, bytes]:
    """Seed inputs by file name (fuzz/transcode_fuzz.c reads the first byte as the mode)."""
    found = {}
    for i, (pair, compiled) in enumerate(programs):
        payload = distinctive(pair.gz_type).SerializeToString()
        found[f"program{i:02d}-empty"] = bytes([i])
        found[f"program{i:02d}-distinctive"] = bytes([i]) + payload
        words = compiled.schema + compiled.ops
        split = struct.pack("<I", len(compiled.schema) // 4)
        found[f"load{i:02d}"] = bytes([LOAD_MODE]) + split + words
        # Mutate mode: program i, no edit (the edit count byte is 0), then the payload.
        found[f"mutate{i:02d}"] = bytes([MUTATE_MODE, i, 0]) + payload
        for name, hostile in _hostile_payloads(pair.gz_type, payload).items():
            found[f"program{i:02d}-{name}"] = bytes([i]) + hostile
    return found


#: A small unknown field (number 2000, a one-byte varint), the filler of costly payloads.
_JUNK_FIELD = bytes([0x80, 0x7D, 0x01])


def _hostile_payloads(gz_type: str, payload: bytes) -> dict[str, bytes]:
    """Payloads shaped to cost (docs/native.md §4): many small unknown fields around a message,
    and per repeated submessage field, thousands of empty elements (an output many times the
    payload, which the transcoder refuses)."""
    junk = _JUNK_FIELD * 2000
    found = {"unknown": junk + payload + junk}
    for field in message_class(gz_type).DESCRIPTOR.fields:
        if field.message_type is not None and field.is_repeated:
            empty = _varint(field.number << 3 | 2) + b"\0"
            found[f"empty-{field.name}"] = payload + empty * 4000
    return found


def _varint(value: int) -> bytes:
    out = bytearray()
    while value > 0x7F:
        out.append(value & 0x7F | 0x80)
        value >>= 7
    out.append(value)
    return bytes(out)


def encoders_header_text(encoders: Sequence[tuple[Pair, bytes]]) -> str:
    """The C header of the encoders: one words array per encoder, and the table of them."""
    lines = ["/* Generated by tools/native_fuzz_programs.py: do not edit, do not commit. */\n"]
    lines.append("#include <stddef.h>\n#include <stdint.h>\n\n")
    for i, (_pair, words) in enumerate(encoders):
        lines.append(_words(f"encoder_{i}", words))
    lines.append("\nstruct fuzz_encoder {\n    const char *name;\n")
    lines.append("    const int32_t *words;\n    size_t len;\n};\n\n")
    lines.append("static const struct fuzz_encoder ENCODERS[] = {\n")
    for i, (pair, words) in enumerate(encoders):
        lines.append(
            f'    {{"{pair.ros_type} -> {pair.gz_type}", encoder_{i}, {len(words) // 4}}},\n'
        )
    lines.append("};\n")
    lines.append(f"#define ENCODER_COUNT {len(encoders)}\n")
    return "".join(lines)


def encoder_seeds(encoders: Sequence[tuple[Pair, bytes]]) -> dict[str, bytes]:
    """Seed inputs of fuzz/encode_fuzz.c by file name (its comment says how they are read)."""
    # Here only: fuzz/loop_fuzz.c's Python imports this module, and loads no ROS library.
    from rclpy.serialization import serialize_message  # noqa: PLC0415

    found = {}
    for i, (pair, words) in enumerate(encoders):
        cdr_default = serialize_message(pair.ros_class())
        cdr_full = serialize_message(distinctive_ros(pair.ros_class))
        found[f"encoder{i:02d}-default"] = bytes([i]) + cdr_default
        found[f"encoder{i:02d}-distinctive"] = bytes([i]) + cdr_full
        length = struct.pack("<I", len(words) // 4)
        found[f"load{i:02d}"] = bytes([LOAD_MODE]) + length + words + cdr_full[4:]
        # Mutate mode: encoder i, no edit (the edit count byte is 0), then the message.
        found[f"mutate{i:02d}"] = bytes([MUTATE_MODE, i, 0]) + cdr_full
    for name, (ops, body) in _SYNTHETIC.items():
        found[f"load-{name}"] = struct.pack(f"<BI{len(ops)}i", LOAD_MODE, len(ops), *ops) + body
    return found


def _encoder_words(nslots: int, read: list[int], write: list[int]) -> list[int]:
    return [nslots, len(read) + 1, *read, ReadOp.END, *write, WriteOp.END]


#: Encoders no pair compiles to, with a CDR body for each, as seeds of the load mode: the ops
#: and types the compiled ones leave out (string sequences, 16-bit and 8-bit integers, a
#: wrapped uint32, zigzag and fixed fields, nested message sequences).
_SYNTHETIC: dict[str, tuple[list[int], bytes]] = {
    "string-sequence": (
        _encoder_words(1, [ReadOp.SEQ_STR, 0], [WriteOp.SEQ_STR, 1, 0]),
        struct.pack("<II", 2, 2) + b"a\0\0\0" + struct.pack("<I", 3) + b"bc\0",
    ),
    "integers": (
        _encoder_words(
            4,
            [ReadOp.NUM, RosKind.INT16, 0, ReadOp.NUM, RosKind.UINT32, 1,
             ReadOp.SEQ_NUM, RosKind.INT8, 2, ReadOp.ARR, RosKind.UINT16, 3, 3],
            [WriteOp.NUM, 1, PbType.SINT32, RosKind.INT16, Conv.EXACT, 0,
             WriteOp.NUM, 2, PbType.UINT32, RosKind.UINT32, Conv.WRAP, 1,
             WriteOp.PACKED, 3, PbType.SINT64, RosKind.INT8, 2,
             WriteOp.PACKED, 4, PbType.FIXED32, RosKind.UINT16, 3],
        ),
        struct.pack("<hxxIIbbbxhhh", -5, 2**32 - 1, 3, -1, 0, 1, 7, -1, 300),
    ),
    "nested-sequences": (
        _encoder_words(
            1,
            [ReadOp.SEQ_MSG, 0, 2, 6, ReadOp.NUM, RosKind.INT32, 0, ReadOp.STR, 1, ReadOp.END],
            [WriteOp.SEQ_MSG, 1, 0, 2, 10,
             WriteOp.NUM, 1, PbType.ENUM, RosKind.INT32, Conv.EXACT, 0, WriteOp.STR, 2, 1,
             WriteOp.END],
        ),
        struct.pack("<Ii", 2, -3) + struct.pack("<I", 2) + b"x\0\0\0" + struct.pack("<iI", 9, 1)
        + b"\0",
    ),
}  # fmt: skip


#: fuzz/loop_fuzz.c's operations, and the frames of its dictionary (its comment says how an
#: input is read).
_MESSAGE, _TURN, _TAKE, _FLOOD, _FORGET, _WATCH, _PUBLISH_FAILS, _BREAK = range(8)
_TOPIC, _PREFIXED, _SENDER, _OTHER_SENDER, _GZ, _IGNITION, _PAYLOAD, _LARGE = (
    0x80, 0x81, 0x83, 0x84, 0x89, 0x8A, 0x8B, 0x8D,
)  # fmt: skip
#: A turn's byte: 8 messages, the socket fired; and the same with the monitor's event.
_READ, _READ_MONITOR = 0x0F, 0x3F


def _loop_message(*frames: int | bytes) -> bytes:
    """A MESSAGE operation: dictionary frames by index, literal frames by their bytes."""
    out = bytearray([_MESSAGE, len(frames) - 1])
    for frame in frames:
        if isinstance(frame, int):
            out += bytes([frame])
        else:
            out += bytes([0x70]) + struct.pack("<H", len(frame)) + frame
    return bytes(out)


def loop_seeds(programs: Sequence[tuple[Pair, Compiled]]) -> dict[str, bytes]:
    """Seed inputs of fuzz/loop_fuzz.c by file name: 4 bytes of configuration (program,
    capacity, byte bound, flags), then operations."""
    data = _loop_message(_TOPIC, _SENDER, _PAYLOAD, _GZ)
    first = data + bytes([_TURN, _READ, _TAKE]) + data + data + bytes([_TURN, _READ, _TAKE])
    found = {}
    for i in range(len(programs)):  # every other one with the loop guard's digests
        found[f"loop{i:02d}-first"] = bytes([i, 7, 20, 0x10 * (i % 2)]) + first
    spelled = _loop_message(_TOPIC, _OTHER_SENDER, b"\x08\x01", _IGNITION)
    found["loop-scripts"] = bytes([0, 1, 6, 0b1110]) + b"".join([
        first, spelled, bytes([_TURN, _READ_MONITOR, _TAKE]), spelled * 3,
        _loop_message(_TOPIC, _SENDER, _LARGE, 3, _GZ), bytes([_TURN, _READ]),
        bytes([_PUBLISH_FAILS]), data, bytes([_TURN, _READ, _PUBLISH_FAILS]),
        _loop_message(_TOPIC, _SENDER, _PAYLOAD, _GZ, _GZ), bytes([_TURN, _READ, _TAKE]),
        bytes([_WATCH, 0x11]), data, bytes([_TURN, _READ, _TAKE, _BREAK, _TURN, _READ]),
        bytes([_FORGET]), data, bytes([_TURN, _READ, _TAKE]),
    ])  # fmt: skip
    flood = bytes([_FLOOD, 0xFF])
    found["loop-flood"] = bytes([0, 7, 20, 0]) + first + flood + data + bytes([_TURN, _READ, _TAKE])
    prefixed = _loop_message(_PREFIXED, _SENDER, _PAYLOAD, _GZ)
    found["loop-prefixed-topic"] = bytes([0, 7, 20, 0]) + b"".join([
        prefixed, bytes([_TURN, _READ, _TAKE]), data, bytes([_TURN, _READ, _TAKE]),
    ])  # fmt: skip
    return found


def _ros_message(publisher: int, cdr: bytes) -> bytes:
    """A MESSAGE operation of a RosPump input: its publisher, rcl tells of it, its CDR bytes."""
    return bytes([_MESSAGE, 0x08 | publisher, 0x70]) + struct.pack("<H", len(cdr)) + cdr


def loop_ros_seeds(encoders: Sequence[tuple[Pair, bytes]]) -> dict[str, bytes]:
    """Seed inputs of fuzz/loop_fuzz.c's RosPump (the configuration's last byte 0x80 and up):
    per encoder, messages sent in every spelling, one of the bridge's own, one refused."""
    from rclpy.serialization import serialize_message  # noqa: PLC0415 - see encoder_seeds

    found = {}
    all_active, own, sends_fail, python_send = (
        bytes([_FLOOD, 0xFF]), bytes([_FORGET, 0x02]), bytes([_WATCH, 0x49]),
        bytes([_PUBLISH_FAILS, 0]),
    )  # fmt: skip
    for i, (pair, _words) in enumerate(encoders):
        cdr = serialize_message(distinctive_ros(pair.ros_class))
        found[f"loop-ros{i:02d}"] = bytes([i, 0x0B, 0x08, 0x80]) + b"".join([
            all_active, own, _ros_message(0, cdr), _ros_message(1, cdr), _ros_message(2, b"\0\1"),
            bytes([_TURN, _READ, _TAKE]), sends_fail, _ros_message(0, cdr) * 3,
            bytes([_TURN, _READ, _BREAK, _TURN, _READ]), python_send, b"\x08\x01",
        ])  # fmt: skip
    return found


def _write(out: Path, header: str, text: str, inputs: dict[str, bytes]) -> Path:
    corpus = out / "corpus"
    corpus.mkdir(parents=True, exist_ok=True)
    (out / header).write_text(text)
    write_c_header(out / "codes.h")
    for name, data in inputs.items():
        (corpus / name).write_bytes(data)
    return corpus


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("out", type=Path, help="directory for the header and corpus/")
    parser.add_argument(
        "--target", choices=("transcode", "encode", "loop"), default="transcode",
        help="the fuzz target: transcode or loop (programs.h), encode (encoders.h)",
    )  # fmt: skip
    args = parser.parse_args(argv)
    if args.target == "encode":
        encoders = compiled_encoders()
        text, inputs = encoders_header_text(encoders), encoder_seeds(encoders)
        header, count = "encoders.h", f"{len(encoders)} encoders"
    else:
        programs = compiled_pairs()
        text = header_text(programs)
        inputs = loop_seeds(programs) if args.target == "loop" else seeds(programs)
        header, count = "programs.h", f"{len(programs)} programs"
    if args.target == "loop":  # it runs a RosPump too, on the encoders
        encoders = compiled_encoders()
        (args.out / "encoders.h").write_text(encoders_header_text(encoders))
        inputs |= loop_ros_seeds(encoders)
    corpus = _write(args.out, header, text, inputs)
    print(f"{count} into {args.out / header}, seeds into {corpus}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

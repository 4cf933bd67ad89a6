"""The native transcoder writes what the Python path writes, and refuses what Python refuses.

For every pair whose program compiles, payloads go through both paths: the native
``Program.to_cdr``, and Python's ``FromString``, ``pair.to_ros`` and the CDR writer. The
outcomes must agree (:func:`check`): native OK means Python writes the same bytes; native
UNDECODABLE means ``FromString`` raises; native CONVERSION means the converter raises
ConversionError; native FALLBACK leaves the decision to Python and is always allowed, but a
well-formed message falls back only where Python does not write it either (a number out of
the ROS type's range: the writer raises and rclpy decides).

Payloads: a message with every field distinct (tools/native_fuzz_programs.py), seeded random
messages in random valid encodings (gz_payloads.py), and malformed variants of valid
payloads. The extension is optional: without it these tests skip, but fail under CI=true.
"""

from __future__ import annotations

import array
import collections
import os
import random
import struct
from collections.abc import Iterable
from typing import Any

import pytest
from google.protobuf.message import DecodeError

from ros_gz_bridge_py import native
from ros_gz_bridge_py.converters.registry import Pair
from ros_gz_bridge_py.errors import ConversionError
from ros_gz_bridge_py.msgs import message_class
from ros_gz_bridge_py.native.codes import Conv, Op, PbType, RosKind
from ros_gz_bridge_py.native.program import Compiled
from ros_gz_bridge_py.ros.cdr_writer import writer_for
from tests.unit.native import gz_payloads as gzp
from tools.native_fuzz_programs import compiled_pairs, distinctive


def require_extension() -> native.Extension:
    """The built extension; skips the module without it, fails instead under CI=true."""
    extension = native.extension()
    if extension is not None:
        return extension
    reason = native.unavailable_reason()
    if os.environ.get("CI", "").lower() == "true":
        pytest.fail(reason, pytrace=False)
    pytest.skip(reason, allow_module_level=True)


_native = require_extension()
OK, UNDECODABLE, CONVERSION, FALLBACK, TOO_LARGE = 0, 1, 2, 3, 4
#: Python's outcome when the converter or the writer refuses a message for another reason than
#: a ConversionError (a number out of range: rclpy then publishes or refuses it).
REFUSED = 5
NAMES = {OK: "OK", UNDECODABLE: "UNDECODABLE", CONVERSION: "CONVERSION", FALLBACK: "FALLBACK"}
NAMES[TOO_LARGE] = "TOO_LARGE"
NAMES[REFUSED] = "REFUSED"
RANDOM_MESSAGES = 200
#: Most single-bit flips tried per payload (all of them for smaller payloads).
FLIPS = 1500
PROGRAM_MUTATIONS = 120
#: The marker character of the distinctive strings (tools/native_fuzz_programs.py).
MARKER = "é".encode()

PAIRS = compiled_pairs()
IDS = [f"{pair.ros_type}-{pair.gz_type}" for pair, _compiled in PAIRS]


class Transcoder:
    """One pair on both paths, and what came out of each so far."""

    def __init__(self, pair: Pair, compiled: Compiled) -> None:
        self.pair = pair
        self.program = _native.Program(compiled.schema, compiled.ops)
        self.gz_class = message_class(pair.gz_type)
        writer = writer_for(pair.ros_class)
        assert writer is not None, f"{pair.ros_type} has no CDR writer"
        self.writer = writer
        self.seen: collections.Counter[tuple[int, int]] = collections.Counter()

    def python(self, payload: bytes) -> tuple[int, bytes | None]:
        """The Python path's outcome and CDR bytes."""
        try:
            gz = self.gz_class.FromString(payload)
        except DecodeError:
            return UNDECODABLE, None
        try:
            ros = self.pair.to_ros(gz)
        except ConversionError:
            return CONVERSION, None
        except (ValueError, TypeError, AssertionError, OverflowError):
            return REFUSED, None
        try:
            return OK, self.writer(ros)
        except Exception:  # any refusal of the writer sends the message through rclpy
            return REFUSED, None

    def check(self, payload: bytes, *, well_formed: bool = False) -> int:
        """Asserts that both paths agree on ``payload``; returns the native status."""
        status: int
        status, cdr = self.program.to_cdr(payload)
        outcome, reference = self.python(payload)
        self.seen[status, outcome] += 1
        where = (
            f"{self.pair.ros_type} <- {self.pair.gz_type}: native {NAMES[status]}, Python "
            f"{NAMES[outcome]}, payload {payload.hex()}"
        )
        if status == OK:
            assert outcome == OK, where
            assert cdr == reference, f"{where}\nnative {cdr!r}\nPython {reference!r}"
        elif status in (UNDECODABLE, CONVERSION):
            assert outcome == status, where
        elif status == TOO_LARGE:  # refused natively only where Python refuses too
            assert outcome == CONVERSION, where
        else:
            assert status == FALLBACK, where
            assert not (well_formed and outcome == OK), f"well-formed message fell back: {where}"
        return status

    def check_all(self, payloads: Iterable[bytes]) -> None:
        for payload in payloads:
            self.check(payload)


@pytest.fixture(params=PAIRS, ids=IDS)
def transcoder(request: pytest.FixtureRequest) -> Transcoder:
    pair, compiled = request.param
    return Transcoder(pair, compiled)


def _seed(transcoder: Transcoder, salt: str) -> random.Random:
    return random.Random(f"{salt}:{transcoder.pair.ros_type}:{transcoder.pair.gz_type}")


def test_most_pairs_compile() -> None:
    """A guard for the parametrized tests below: they cover the pairs that compile."""
    assert len(PAIRS) >= 40


def test_distinctive_message_is_written_alike(transcoder: Transcoder) -> None:
    payload = distinctive(transcoder.pair.gz_type).SerializeToString()
    assert transcoder.check(payload, well_formed=True) == OK
    assert transcoder.check(b"", well_formed=True) == OK


def test_random_messages_in_random_encodings_are_written_alike(transcoder: Transcoder) -> None:
    rng = _seed(transcoder, "random")
    for _ in range(RANDOM_MESSAGES):
        msg = gzp.random_fill(transcoder.gz_class(), rng)
        transcoder.check(msg.SerializeToString(), well_formed=True)
        transcoder.check(gzp.encode(msg, rng), well_formed=True)
    assert transcoder.seen[OK, OK] > 0, transcoder.seen


def test_truncated_and_bit_flipped_payloads_agree(transcoder: Transcoder) -> None:
    rng = _seed(transcoder, "damage")
    payload = distinctive(transcoder.pair.gz_type).SerializeToString()
    transcoder.check_all(gzp.truncations(payload))
    transcoder.check_all(gzp.bit_flips(payload, rng, FLIPS))
    if len(payload) > 1:
        assert transcoder.seen[UNDECODABLE, UNDECODABLE] > 0, transcoder.seen


def test_random_bytes_agree(transcoder: Transcoder) -> None:
    rng = _seed(transcoder, "bytes")
    transcoder.check_all(rng.randbytes(rng.randrange(1, 64)) for _ in range(300))


def test_ill_formed_utf8_is_undecodable(transcoder: Transcoder) -> None:
    payload = distinctive(transcoder.pair.gz_type).SerializeToString()
    for bad in gzp.bad_utf8(payload, MARKER):
        assert transcoder.check(bad) in (UNDECODABLE, FALLBACK)
    # Ill-formed UTF-8 in an unknown field is kept aside, never checked.
    unknown = gzp.length_delimited(2**29 - 1, b"\xc3\x28\xff")
    assert transcoder.check(payload + unknown, well_formed=True) == OK


def test_oversized_lengths_are_undecodable(transcoder: Transcoder) -> None:
    payload = distinctive(transcoder.pair.gz_type).SerializeToString()
    for bad in gzp.oversized_lengths(payload):
        assert transcoder.check(bad) in (UNDECODABLE, FALLBACK)


def test_lengths_longer_than_five_bytes_are_refused(transcoder: Transcoder) -> None:
    """A length may take more bytes than needed, up to 5: the runtime refuses 6 or more."""
    payload = distinctive(transcoder.pair.gz_type).SerializeToString()
    unknown = gzp.tag(2**29 - 1, gzp.LEN)
    for size in (2, 5):
        assert transcoder.check(payload + unknown + gzp.varint(2, size - 1) + b"ab") == OK
        for longer in gzp.long_lengths(payload, size):
            assert transcoder.check(longer, well_formed=True) == OK
    for size in (6, 10):
        cases = [payload + unknown + gzp.varint(2, size - 1) + b"ab"]
        for longer in [*cases, *gzp.long_lengths(payload, size)]:
            assert transcoder.check(longer) in (UNDECODABLE, FALLBACK)
            assert transcoder.python(longer)[0] == UNDECODABLE


def test_unknown_fields_are_skipped(transcoder: Transcoder) -> None:
    payload = distinctive(transcoder.pair.gz_type).SerializeToString()
    unused = 2**29 - 1
    for unknown in (
        gzp.tag(unused, gzp.VARINT) + gzp.varint(-1),
        gzp.tag(unused, gzp.I64) + bytes(range(8)),
        gzp.tag(unused, gzp.I32) + bytes(4),
        gzp.length_delimited(unused, b"\x08\x96\x01"),
        gzp.length_delimited(unused, b""),
    ):
        assert transcoder.check(unknown + payload + unknown, well_formed=True) == OK
        # Cut inside the unknown field: undecodable wherever it is.
        transcoder.check(payload + unknown[:-1])


def test_packed_and_unpacked_repeated_numbers_agree(transcoder: Transcoder) -> None:
    rng = _seed(transcoder, "packing")
    msg = distinctive(transcoder.pair.gz_type)
    for _ in range(20):
        assert transcoder.check(gzp.encode(msg, rng), well_formed=True) == OK


#: Floats whose conversion to double must keep every bit the Python path keeps.
_COVARIANCE = [0.01, -0.0, float("inf"), float("-inf"), 1e-45, 3.4e38, -2.5, 0.0]
_COVARIANCE_NAN = struct.pack("<I", 0x7FA00001)  # a signalling NaN with a payload


def _float_runs(values: list[bytes], runs: list[int]) -> bytes:
    """A Float_V's data (field 2) as packed runs of the given lengths (0: one unpacked value)."""
    out, at = b"", 0
    for run in runs:
        if run == 0:
            out += gzp.tag(2, gzp.I32) + values[at]
            at += 1
        else:
            out += gzp.length_delimited(2, b"".join(values[at : at + run]))
            at += run
    return out


def test_covariances_in_any_encoding_are_written_alike() -> None:
    """A fixed list of doubles sent as one packed run of its length is written in one pass
    (transcode.c packed_doubles); in any other form, element by element. Both as Python."""
    pair = next(p for p, _ in PAIRS if p.gz_type == "gz.msgs.IMU")
    transcoder = Transcoder(pair, next(c for p, c in PAIRS if p is pair))
    nine = [struct.pack("<f", v) for v in _COVARIANCE] + [_COVARIANCE_NAN]
    values = [*nine, nine[0]]  # a tenth for the list that is too long
    for runs in ([9], [4, 5], [0] * 9, [3, 0, 5], [8], [9, 1], []):
        covariance = _float_runs(values, runs)
        payload = b"".join(gzp.length_delimited(n, covariance) for n in (4, 6, 8))
        assert transcoder.check(payload, well_formed=True) == OK, runs


def test_odd_tags_wrong_wire_types_and_merged_submessages_agree(transcoder: Transcoder) -> None:
    payload = distinctive(transcoder.pair.gz_type).SerializeToString()
    transcoder.check_all(payload + odd for odd in gzp.odd_tags())
    transcoder.check_all(odd + payload for odd in gzp.odd_tags())
    transcoder.check_all(gzp.wrong_wire_types(payload))
    # A singular submessage twice: the runtime merges the two.
    for start, _number, wire, _head in gzp.top_fields(payload):
        if wire == gzp.LEN:
            end = next((s for s, *_ in gzp.top_fields(payload) if s > start), len(payload))
            transcoder.check(payload + payload[start:end])


def test_strings_with_a_nul_agree(transcoder: Transcoder) -> None:
    """A NUL inside a string is valid protobuf; native leaves it to Python."""
    payload = distinctive(transcoder.pair.gz_type).SerializeToString()
    at = payload.find(MARKER)
    if at < 0:
        pytest.skip(f"{transcoder.pair.gz_type} has no string field")
    status = transcoder.check(payload[:at] + b"\0\0" + payload[at + 2 :])
    assert status in (OK, FALLBACK)


def _words(data: bytes) -> array.array[int]:
    """The words of a program, unsigned (so that any bit may flip)."""
    return array.array("I", data)


def _run_if_loaded(schema: bytes, ops: bytes, payloads: list[bytes]) -> bool:
    """Loads the words; where they load, runs them on ``payloads``. Whether they loaded."""
    try:
        program: Any = _native.Program(schema, ops)
    except ValueError:
        return False
    for payload in payloads:
        status, cdr = program.to_cdr(payload)
        assert status in (OK, UNDECODABLE, CONVERSION, FALLBACK)
        assert (cdr is not None) == (status == OK)
    return True


def test_text_lengths_near_the_int32_limit_are_refused() -> None:
    """The words a text takes are counted without overflow (found by fuzz/transcode_fuzz.c)."""
    schema = PAIRS[0][1].schema
    for length in (2**31 - 1, 2**31 - 3, 2**31 - 4, -1):
        ops = array.array("i", [Op.CONST_STR, length, Op.END])
        with pytest.raises(ValueError, match="not a native program"):
            _native.Program(schema, ops.tobytes())


@pytest.mark.parametrize(("pair", "compiled"), PAIRS, ids=IDS)
def test_damaged_programs_are_refused(pair: Pair, compiled: Compiled) -> None:
    schema, ops = compiled.schema, compiled.ops
    for cut in range(0, len(schema), 4):
        with pytest.raises(ValueError, match="not a native program"):
            _native.Program(schema[:cut], ops)
    for cut in range(0, len(ops), 4):
        with pytest.raises(ValueError, match="not a native program"):
            _native.Program(schema, ops[:cut])
    with pytest.raises(ValueError, match="int32 words"):
        _native.Program(schema, ops + b"\0")
    rng = random.Random(f"programs:{pair.ros_type}:{pair.gz_type}")
    payloads = [b"", distinctive(pair.gz_type).SerializeToString()]
    loaded = 0
    for _ in range(PROGRAM_MUTATIONS):
        words = [_words(schema), _words(ops)]
        part = words[rng.randrange(2)]
        at = rng.randrange(len(part))
        if rng.random() < 0.5:
            part[at] ^= 1 << rng.randrange(32)
        else:
            word = rng.choice([-1, 0, 1, 2, 3, 8, 11, 64, 65, 2**31, rng.randrange(-9, 99)])
            part[at] = word % 2**32
        loaded += _run_if_loaded(words[0].tobytes(), words[1].tobytes(), payloads)
    assert loaded < PROGRAM_MUTATIONS


def test_a_header_lookup_that_reaches_a_number_falls_back() -> None:
    """rgb_load does not match paths with the schema: a header lookup whose path leads to a
    Time, where field 2 is a number and not a Header's entries, must leave the payload to
    Python (it once read an unset view there)."""
    compiled = next(c for p, c in PAIRS if p.gz_type == "gz.msgs.Header")
    key = b"frame_id"
    # path [stamp], last entry, the key's length and bytes, an empty default, the end
    ops = array.array("i", [Op.HEADER_STR, 1, 1, 1, len(key)])
    ops.frombytes(key)
    ops.extend([0, Op.END])
    program = _native.Program(compiled.schema, ops.tobytes())
    stamp = gzp.length_delimited(1, gzp.tag(2, gzp.VARINT) + gzp.varint(5))
    assert program.to_cdr(stamp) == (FALLBACK, None)


def test_submessages_past_the_eager_index_are_read_alike() -> None:
    """Validation indexes the singular submessages it passes while the index is small (16 KiB,
    pb_read.c); past that, a path indexes them when it reaches them. Under a type of 64 fields
    (4 KiB an index), nesting it 7 deep passes the bound: a number at depth 1 and one at depth
    7 are read alike, whichever side of the bound their messages were indexed on."""
    fields = [[number, PbType.MESSAGE, 0, 0] for number in range(1, 64)]
    fields.append([64, PbType.INT32, 0, -1])
    schema = array.array("i", [1, 2, 64, *[word for field in fields for word in field]])

    def read_at(depth: int) -> list[int]:
        return [Op.NUM, depth, *[1] * depth, 64, PbType.INT32, RosKind.INT32, Conv.EXACT]

    ops = array.array("i", [*read_at(1), *read_at(7), Op.END])
    program = _native.Program(schema.tobytes(), ops.tobytes())
    deep = gzp.tag(64, gzp.VARINT) + gzp.varint(77)
    for _ in range(6):
        deep = gzp.length_delimited(1, deep)
    shallow = gzp.tag(64, gzp.VARINT) + gzp.varint(11)
    expected = bytes([0, 1, 0, 0]) + struct.pack("<ii", 11, 77)
    for level_one in (shallow + deep, deep + shallow):  # the depth-1 value before or after
        assert program.to_cdr(gzp.length_delimited(1, level_one)) == (OK, expected)

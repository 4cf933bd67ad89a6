"""The native ROS -> Gazebo encoder writes, for every pair it compiles, exactly the payload of the
Python path (light reader, converter, protobuf serialization), and leaves to Python what it does
not decide (docs/native.md §6).

The agreement rule (:meth:`Encoding.check`): native OK means Python writes the same payload;
native UNDECODABLE means Python refuses the message (any error of the light reader or the
converter); native FALLBACK leaves the decision to Python and is always allowed, but not for
a well-formed message (rclpy's or the CDR writer's). Messages: random ones, one with every
field distinct (tools/native_fuzz_programs.py), and what an attacker could send instead: cut
or bit-flipped messages, huge counts and string lengths, strings without their NUL or with one
inside, bad UTF-8, bool bytes other than 0 and 1, other encapsulations, floats of every class.
fuzz/encode_fuzz.c runs the same encoders under the sanitizers (test_fuzz.py).
"""

from __future__ import annotations

import collections
import math
import random
import re
import struct
from collections.abc import Iterable, Iterator
from typing import Any

import pytest
from rclpy.serialization import serialize_message

from ros_gz_bridge_py.converters.registry import Pair
from ros_gz_bridge_py.ros import cdr_types as cdr
from ros_gz_bridge_py.ros import light_reader
from ros_gz_bridge_py.ros.cdr_writer import writer_for
from tests.unit.native import gz_payloads as gzp
from tools.native_fuzz_programs import compiled_encoders, distinctive_ros

OK, UNDECODABLE, FALLBACK = 0, 1, 3
NAMES = {OK: "OK", UNDECODABLE: "UNDECODABLE", FALLBACK: "FALLBACK"}
#: Messages per pair, and the seed that makes them.
MESSAGES = 150
SEED = 20261127
#: Most single-bit flips tried per message (all of them for smaller messages).
FLIPS = 1500
_INTEGERS = {
    "int8": (-(2**7), 2**7 - 1),
    "uint8": (0, 2**8 - 1),
    "int16": (-(2**15), 2**15 - 1),
    "uint16": (0, 2**16 - 1),
    "int32": (-(2**31), 2**31 - 1),
    "uint32": (0, 2**32 - 1),
    "int64": (-(2**63), 2**63 - 1),
    "uint64": (0, 2**64 - 1),
}
_FLOATS = (0.0, -0.0, 1.5, -2.25e10, math.inf, -math.inf, math.nan, 1e-45, 3.0e38)
_TEXTS = ("", "frame", "world::robot/base", "é漢字", "x" * 70)
#: A string of :func:`~tools.native_fuzz_programs.distinctive_ros`: its text and its NUL.
_DISTINCTIVE_TEXT = re.compile(rb"s\d+(?:::part::)?\xc3\xa9\x00")
#: A value no float or double field of a default message has, exact in both widths.
_SENTINEL = 1234.5
_FLT_MAX = struct.unpack("<f", struct.pack("<I", 0x7F7FFFFF))[0]
#: Double bit patterns: zeros, infinities, NaNs (signalling, with a payload, negative), the
#: extremes, and values around the float range's edges (for double -> float fields: rounding
#: to FLT_MAX or to infinity, to the smallest subnormal or to zero).
_DOUBLE_BITS = (
    0, 1 << 63, 0x7FF0000000000000, 0xFFF0000000000000, 0x7FF8000000000000,
    0x7FF0000000000001, 0x7FF8DEADBEEF0001, 0xFFF8000000000123, 0x7FEFFFFFFFFFFFFF, 1,
    0x800FFFFFFFFFFFFF,
    *(
        struct.unpack("<Q", struct.pack("<d", value))[0]
        for value in (
            _FLT_MAX, _FLT_MAX * (1 + 2**-25), _FLT_MAX * (1 + 2**-24), -_FLT_MAX * (1 + 2**-23),
            1e-46, -1e-46, 7.1e-46, 1.4e-45, 0.1,
        )
    ),
)  # fmt: skip
#: Float bit patterns: zeros, infinities, NaNs (signalling, with a payload, negative), the
#: extremes.
_FLOAT_BITS = (
    0, 1 << 31, 0x7F800000, 0xFF800000, 0x7FC00000, 0x7F800001, 0x7FC0BEEF, 0xFFC00001,
    0x7F7FFFFF, 1, 0x807FFFFF,
)  # fmt: skip
#: Encapsulations other than classic little-endian CDR (docs/cdr.md §1): big-endian CDR,
#: parameter lists, XCDR2, and kinds that do not exist.
_OTHER_ENCAPSULATIONS = (
    b"\x00\x00", b"\x00\x02", b"\x00\x03", b"\x00\x07", b"\x00\x0b", b"\x01\x01", b"\xff\x01",
    b"\x00\xff",
)  # fmt: skip
#: Text of the same UTF-8 length as "part" (4 bytes) that Python does not decode: a surrogate,
#: overlong forms, a code point above U+10FFFF, a lone continuation, a cut sequence.
_BAD_UTF8 = (
    b"\xed\xa0\x80a", b"\xe0\x80\x80a", b"\xf0\x80\x80\x80", b"\xf4\x90\x80\x80",
    b"\xc0\x80ab", b"a\x80bc", b"abc\xe2", b"\xf5\x80\x80\x80", b"\xff\xfeab",
)  # fmt: skip
#: And text of that length Python decodes: the first and last code points of each length.
_GOOD_UTF8 = (
    b"\xc2\x80\xdf\xbf", b"\xe0\xa0\x80a", b"\xef\xbf\xbfa", b"\xf0\x90\x80\x80",
    b"\xf4\x8f\xbf\xbf", b"\xed\x9f\xbfa", b"\xee\x80\x80a",
)  # fmt: skip
#: Values written over each uint32 of a message (its counts and string lengths among them).
_HUGE = (0xFFFFFFFF, 0x80000000, 0x7FFFFFFF, 0x10000, 0)

COMPILED = compiled_encoders()
IDS = [f"{pair.ros_type}-{pair.gz_type}" for pair, _ in COMPILED]


def _python(pair: Pair, data: bytes) -> bytes | Exception:
    """What the Python path sends for ``data``: the payload, or the error it counts."""
    try:
        tree = light_reader.read(data, pair.ros_class)
        payload: bytes = pair.to_gz(tree).SerializeToString()
    except Exception as err:  # the channel counts any error of the converter
        return err
    return payload


class Encoding:
    """One pair on both paths, and what came out of each so far."""

    def __init__(self, native: Any, pair: Pair, words: bytes) -> None:
        self.pair = pair
        self.encoder = native.Encoder(words)
        self.seen: collections.Counter[tuple[int, bool]] = collections.Counter()

    def check(self, data: bytes, *, well_formed: bool = False) -> int:
        """Asserts that both paths agree on ``data``; returns the native status."""
        status: int
        status, payload = self.encoder.to_pb(data)
        reference = _python(self.pair, data)
        refused = isinstance(reference, Exception)
        self.seen[status, refused] += 1
        where = (
            f"{self.pair.ros_type} -> {self.pair.gz_type}: native {NAMES[status]}, Python "
            f"{reference!r}, CDR {data.hex()}"
        )
        assert (payload is not None) == (status == OK), where
        if status == OK:
            assert payload == reference, f"{where}\nnative {payload!r}"
        elif status == UNDECODABLE:
            assert refused, where
        else:
            assert status == FALLBACK, where
            assert not well_formed, f"a well-formed message fell back: {where}"
        return status

    def check_all(self, variants: Iterable[bytes]) -> None:
        for data in variants:
            self.check(data)


@pytest.fixture(params=COMPILED, ids=IDS)
def encoding(native: Any, request: pytest.FixtureRequest) -> Encoding:
    pair, words = request.param
    return Encoding(native, pair, words)


def _seed(encoding: Encoding, salt: str) -> random.Random:
    return random.Random(f"{SEED} {salt} {encoding.pair.ros_type} {encoding.pair.gz_type}")


def _value(rng: random.Random, basic: str) -> Any:
    if basic in ("double", "float"):
        return rng.choice((*_FLOATS, rng.uniform(-1e6, 1e6)))
    if basic == "boolean":
        return rng.random() < 0.5
    low, high = _INTEGERS[basic]
    return rng.choice((0, low, high, rng.randint(low, high)))


def _fill(msg: Any, rng: random.Random, depth: int = 0) -> Any:
    """Every field of ``msg`` (most of them) set to a random value of its type."""
    for name, rosidl in cdr.fields_of(type(msg)):
        kind, basic = type(rosidl).__name__, cdr.basic_of(rosidl)
        if rng.random() < 0.1 or basic in ("char", "octet"):
            continue
        if basic is not None:
            setattr(msg, name, _value(rng, basic))
        elif kind in cdr.STRING_TYPES:
            setattr(msg, name, rng.choice(_TEXTS))
        elif kind == "NamespacedType":
            _fill(getattr(msg, name), rng, depth + 1)
        elif kind == "Array" and cdr.basic_of(rosidl.value_type) not in (None, "char", "octet"):
            setattr(
                msg, name, [_value(rng, rosidl.value_type.typename) for _ in range(rosidl.size)]
            )
        elif kind in cdr.SEQUENCE_TYPES:
            _fill_sequence(msg, name, rosidl.value_type, rng, depth)
    return msg


def _fill_sequence(msg: Any, name: str, element: Any, rng: random.Random, depth: int) -> None:
    count = rng.randint(0, 3)
    basic = cdr.basic_of(element)
    if basic is not None and basic not in ("char", "octet"):
        setattr(msg, name, [_value(rng, basic) for _ in range(count)])
    elif type(element).__name__ in cdr.STRING_TYPES:
        setattr(msg, name, [rng.choice(_TEXTS) for _ in range(count)])
    elif type(element).__name__ == "NamespacedType" and depth < 3:
        cls = cdr.nested_class(element)
        setattr(msg, name, [_fill(cls(), rng, depth + 1) for _ in range(count)])


def _floats_set(msg: Any, value: float) -> Any:
    """``msg`` with every float and double field (one element per sequence) set to ``value``."""
    for name, rosidl in cdr.fields_of(type(msg)):
        kind, basic = type(rosidl).__name__, cdr.basic_of(rosidl)
        element = getattr(rosidl, "value_type", None)
        if basic in ("float", "double"):
            setattr(msg, name, value)
        elif kind == "NamespacedType":
            _floats_set(getattr(msg, name), value)
        elif kind == "Array" and cdr.basic_of(element) in ("float", "double"):
            setattr(msg, name, [value] * rosidl.size)
        elif kind in cdr.SEQUENCE_TYPES and cdr.basic_of(element) in ("float", "double"):
            setattr(msg, name, [value])
        elif kind in cdr.SEQUENCE_TYPES and type(element).__name__ == "NamespacedType":
            setattr(msg, name, [_floats_set(cdr.nested_class(element)(), value)])
    return msg


def _written(msg: Any) -> bytes:
    """``msg`` in CDR, its padding zero (rclpy leaves whatever its buffer held there, which
    could look like the distinctive strings or the float sentinels)."""
    writer = writer_for(type(msg))
    assert writer is not None, f"{type(msg).__name__} has no CDR writer"
    return writer(msg)


def _distinctive(pair: Pair) -> bytes:
    return _written(distinctive_ros(pair.ros_class))


def _aligned_replace(data: bytes, old: bytes, new: bytes) -> bytes:
    """``data`` with each ``old`` aligned to its size (a value of that size) made ``new``."""
    out = bytearray(data)
    for at in range(len(cdr.CDR_LE_HEADER), len(data) - len(old) + 1, len(old)):
        if data[at : at + len(old)] == old:
            out[at : at + len(old)] = new
    return bytes(out)


def _texts(data: bytes) -> Iterator[tuple[int, int]]:
    """(offset of the length, offset of the NUL) of each string of a distinctive message."""
    for match in _DISTINCTIVE_TEXT.finditer(data):
        start, end = match.span()
        (length,) = struct.unpack_from("<I", data, start - 4)
        assert length == end - start, "a distinctive string not preceded by its length"
        yield start - 4, end - 1


def _replaced(data: bytes, at: int, new: bytes) -> bytes:
    return data[:at] + new + data[at + len(new) :]


def test_the_required_pairs_compile() -> None:
    compiled = {(pair.ros_type, pair.gz_type) for pair, _ in COMPILED}
    for wanted in (
        ("geometry_msgs/msg/Twist", "gz.msgs.Twist"),
        ("geometry_msgs/msg/TwistStamped", "gz.msgs.Twist"),
        ("geometry_msgs/msg/Pose", "gz.msgs.Pose"),
        ("geometry_msgs/msg/PoseStamped", "gz.msgs.Pose"),
        ("nav_msgs/msg/Odometry", "gz.msgs.Odometry"),
        ("rosgraph_msgs/msg/Clock", "gz.msgs.Clock"),
        ("sensor_msgs/msg/Imu", "gz.msgs.IMU"),
        ("sensor_msgs/msg/Imu", "ignition.msgs.IMU"),
        ("std_msgs/msg/Float64", "gz.msgs.Double"),
        ("std_msgs/msg/Bool", "gz.msgs.Boolean"),
        ("std_msgs/msg/Int32", "gz.msgs.Int32"),
        ("std_msgs/msg/String", "gz.msgs.StringMsg"),
    ):
        assert wanted in compiled


def test_random_messages_are_written_alike(encoding: Encoding) -> None:
    rng = _seed(encoding, "random")
    for _ in range(MESSAGES):
        encoding.check(serialize_message(_fill(encoding.pair.ros_class(), rng)), well_formed=True)
    # Every value rclpy serializes is one the encoder takes: nothing fell back.
    assert encoding.seen[OK, False] == MESSAGES, encoding.seen


def test_distinctive_and_default_messages_are_written_alike(encoding: Encoding) -> None:
    data = _distinctive(encoding.pair)
    assert encoding.check(data, well_formed=True) == OK
    # The string tests below find every string of it.
    assert len(list(_texts(data))) == data.count(b"\xc3\xa9\x00")
    default = encoding.pair.ros_class()
    assert encoding.check(serialize_message(default), well_formed=True) == OK
    assert encoding.check(_written(default), well_formed=True) == OK
    # Bytes after the message are not read, by either path.
    assert encoding.check(data + b"\x01\xff\x00trailing", well_formed=True) == OK


def test_cut_and_bit_flipped_messages_agree(encoding: Encoding) -> None:
    rng = _seed(encoding, "damage")
    data = _distinctive(encoding.pair)
    encoding.check_all(gzp.truncations(data))
    encoding.check_all(gzp.bit_flips(data, rng, FLIPS))
    assert encoding.seen[UNDECODABLE, True] > 0, encoding.seen


def test_random_bodies_agree(encoding: Encoding) -> None:
    rng = _seed(encoding, "bytes")
    encoding.check_all(cdr.CDR_LE_HEADER + rng.randbytes(rng.randrange(64)) for _ in range(300))


def test_huge_counts_and_lengths_agree(encoding: Encoding) -> None:
    """Each uint32 of the message (its sequence counts and string lengths among them) replaced
    by a huge or odd value: never a read past the message."""
    data = _distinctive(encoding.pair)
    for at in range(len(cdr.CDR_LE_HEADER), len(data) - 3, 4):
        rest = len(data) - at - 4
        for value in (*_HUGE, rest, rest + 1, len(data)):
            encoding.check(_replaced(data, at, struct.pack("<I", value)))
    if any(_texts(data)):
        assert encoding.seen[UNDECODABLE, True] > 0, encoding.seen


def test_string_lengths_that_miss_the_nul_agree(encoding: Encoding) -> None:
    data = _distinctive(encoding.pair)
    for at, nul in _texts(data):
        length = nul + 1 - (at + 4)
        for wrong in (0, 1, length - 1, length + 1, length + 4, 2**31, 2**32 - 1):
            encoding.check(_replaced(data, at, struct.pack("<I", wrong)))


def test_strings_without_their_nul_or_with_one_inside_agree(encoding: Encoding) -> None:
    """Python takes a string's bytes up to its first NUL, all of them without one, as rclpy
    does: the encoder leaves such strings to it."""
    data = _distinctive(encoding.pair)
    for at, nul in _texts(data):
        start = at + 4
        for variant in (
            _replaced(data, nul, b"x"),
            _replaced(data, start, b"\x00"),
            _replaced(data, nul - 2, b"\x00"),
            _replaced(data, start, b"\x00" * (nul - start)),
        ):
            assert encoding.check(variant) in (OK, FALLBACK)


def test_ill_formed_utf8_is_refused_and_well_formed_utf8_agrees(encoding: Encoding) -> None:
    data = _distinctive(encoding.pair)
    for at, nul in _texts(data):
        part = data.find(b"part", at, nul)
        for bad in _BAD_UTF8:
            if part >= 0:
                assert encoding.check(_replaced(data, part, bad)) in (UNDECODABLE, FALLBACK)
        # The marker "é" just before the NUL, cut or made ill-formed.
        for bad in (b"\xc3\x28", b"\xc3\xc3", b"\xa9\xa9", b"\xe2\x82", b"\xf0\x9f"):
            assert encoding.check(_replaced(data, nul - 2, bad)) in (UNDECODABLE, FALLBACK)
        for good in _GOOD_UTF8:
            if part >= 0:
                assert encoding.check(_replaced(data, part, good), well_formed=True) == OK


def test_bool_bytes_other_than_0_and_1_agree(encoding: Encoding) -> None:
    """Every byte 1 of the message (its true bools among them) as 2, 0x80 and 0xff."""
    data = _distinctive(encoding.pair)
    ones = [at for at in range(len(cdr.CDR_LE_HEADER), len(data)) if data[at] == 1]
    for at in ones:
        encoding.check_all(_replaced(data, at, bytes([other])) for other in (2, 0x80, 0xFF))


def test_other_encapsulations_are_left_to_python(encoding: Encoding) -> None:
    data = _distinctive(encoding.pair)
    for kind in _OTHER_ENCAPSULATIONS:
        status, payload = encoding.encoder.to_pb(kind + data[2:])
        assert (status, payload) == (FALLBACK, None), kind
    # The options (the header's last two bytes) are not read, by either path.
    for options in (b"\x00\x03", b"\xff\xff"):
        assert encoding.check(data[:2] + options + data[4:], well_formed=True) == OK
    for short in (b"", b"\x00", b"\x00\x01", b"\x00\x01\x00"):
        assert encoding.encoder.to_pb(short) == (FALLBACK, None)


def test_floats_of_every_class_are_written_alike(encoding: Encoding) -> None:
    """Every float and double field set to each bit pattern of _DOUBLE_BITS and _FLOAT_BITS (a
    sentinel value, replaced in the serialized message), double -> float fields among them."""
    data = _written(_floats_set(encoding.pair.ros_class(), _SENTINEL))
    doubles, floats = struct.pack("<d", _SENTINEL), struct.pack("<f", _SENTINEL)
    if doubles not in data and floats not in data:
        pytest.skip(f"{encoding.pair.ros_type} has no float field")
    for k in range(max(len(_DOUBLE_BITS), len(_FLOAT_BITS))):
        double_bits = struct.pack("<Q", _DOUBLE_BITS[k % len(_DOUBLE_BITS)])
        float_bits = struct.pack("<I", _FLOAT_BITS[k % len(_FLOAT_BITS)])
        variant = _aligned_replace(_aligned_replace(data, doubles, double_bits), floats, float_bits)
        assert encoding.check(variant, well_formed=True) == OK


def test_an_empty_message_without_its_byte_agrees(native: Any) -> None:
    pair, words = next((p, w) for p, w in COMPILED if p.ros_type == "std_msgs/msg/Empty")
    status, _payload = native.Encoder(words).to_pb(cdr.CDR_LE_HEADER)
    assert status != UNDECODABLE or isinstance(_python(pair, cdr.CDR_LE_HEADER), Exception)


def test_field_numbers_beyond_the_protobuf_range_are_refused(native: Any) -> None:
    """A tag keeps 3 bits for the wire type: field numbers above 2^29 - 1 are not protobuf
    (found by fuzz/encode_fuzz.c)."""
    _pair, words = next((p, w) for p, w in COMPILED if p.ros_type == "std_msgs/msg/Int32")
    values = list(memoryview(words).cast("i"))
    write = 2 + values[1]
    assert values[write] == 1  # W_NUM, then its field number
    for number, loads in ((2**29 - 1, True), (2**29, False), (2**31 - 1, False), (0, False)):
        values[write + 1] = number
        raw = struct.pack(f"<{len(values)}i", *values)
        if loads:
            native.Encoder(raw)
        else:
            with pytest.raises(ValueError, match="not a native encoder"):
                native.Encoder(raw)


def test_damaged_encoders_are_refused_or_run_without_harm(native: Any) -> None:
    rng = random.Random(SEED)
    refused = 0
    for pair, words in COMPILED:
        messages = [cdr.CDR_LE_HEADER + bytes(64), _distinctive(pair)]
        values = list(memoryview(words).cast("i"))
        for _ in range(40):
            damaged = list(values)
            index = rng.randrange(len(damaged))
            nearby = (damaged[index] + 1) % 2**31
            damaged[index] = rng.choice((-1, 0, 1, 7, 2**31 - 1, -(2**31), nearby))
            cut = damaged[: rng.randrange(len(damaged) + 1)]
            for candidate in (damaged, cut):
                raw = struct.pack(f"<{len(candidate)}i", *candidate)
                try:
                    encoder = native.Encoder(raw)
                except ValueError:
                    refused += 1
                    continue
                for data in messages:
                    status, payload = encoder.to_pb(data)
                    assert status in (OK, UNDECODABLE, FALLBACK)
                    assert (payload is not None) == (status == OK)
    assert refused > 0

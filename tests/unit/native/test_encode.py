"""The native ROS -> Gazebo encoder writes, for every pair it compiles, exactly the payload of the
Python path (light reader, converter, protobuf serialization), and leaves to Python what it does
not decide (docs/native.md §6)."""

from __future__ import annotations

import math
import random
from typing import Any

import pytest
from rclpy.serialization import serialize_message

from ros_gz_bridge_py.converters.registry import Pair, default_registry
from ros_gz_bridge_py.native import extension
from ros_gz_bridge_py.native.encoder import compile_to_gz
from ros_gz_bridge_py.native.program import NotExpressibleError
from ros_gz_bridge_py.ros import cdr_types as cdr
from ros_gz_bridge_py.ros import light_reader

OK = 0
#: Messages per pair, and the seed that makes them.
MESSAGES = 150
SEED = 20261127
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


def _compiled() -> list[tuple[Pair, bytes]]:
    found = []
    for pair in default_registry().pairs:
        try:
            found.append((pair, compile_to_gz(pair)))
        except NotExpressibleError:
            continue
    return found


COMPILED = _compiled()


@pytest.fixture(scope="module")
def native() -> Any:
    module = extension()
    if module is None:
        pytest.skip("the native extension is not built (test_native_path.py requires it in CI)")
    return module


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


def _python(pair: Pair, data: bytes) -> bytes | Exception:
    """What the Python path sends for ``data``: the payload, or the error it counts."""
    try:
        tree = light_reader.read(data, pair.ros_class)
        payload: bytes = pair.to_gz(tree).SerializeToString()
    except Exception as err:  # the channel counts any error of the converter
        return err
    return payload


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


@pytest.mark.parametrize(
    ("pair", "words"), COMPILED, ids=[f"{p.ros_type}-{p.gz_type}" for p, _ in COMPILED]
)
def test_random_messages_are_written_alike(native: Any, pair: Pair, words: bytes) -> None:
    encoder = native.Encoder(words)
    rng = random.Random(f"{SEED} {pair.ros_type} {pair.gz_type}")
    encoded = 0
    for _ in range(MESSAGES):
        data = serialize_message(_fill(pair.ros_class(), rng))
        status, payload = encoder.to_pb(data)
        if status == OK:
            encoded += 1
            assert payload == _python(pair, data), pair.ros_type
    # Every value rclpy serializes is one the encoder takes: nothing fell back.
    assert encoded == MESSAGES


@pytest.mark.parametrize(
    ("pair", "words"), COMPILED, ids=[f"{p.ros_type}-{p.gz_type}" for p, _ in COMPILED]
)
def test_cut_and_damaged_messages_are_written_alike_or_left_to_python(
    native: Any, pair: Pair, words: bytes
) -> None:
    encoder = native.Encoder(words)
    rng = random.Random(f"{SEED} damaged {pair.ros_type} {pair.gz_type}")
    data = serialize_message(_fill(pair.ros_class(), rng))
    variants = [data[:end] for end in range(len(data))]
    for _ in range(200):
        damaged = bytearray(data)
        damaged[rng.randrange(len(damaged))] ^= 1 << rng.randrange(8)
        variants.append(bytes(damaged))
    for variant in variants:
        status, payload = encoder.to_pb(variant)
        if status == OK:
            assert payload == _python(pair, variant), (pair.ros_type, variant)


def test_damaged_encoders_are_refused(native: Any) -> None:
    rng = random.Random(SEED)
    for _pair, words in COMPILED:
        values = list(memoryview(words).cast("i"))
        for _ in range(40):
            damaged = list(values)
            index = rng.randrange(len(damaged))
            nearby = (damaged[index] + 1) % 2**31
            damaged[index] = rng.choice((-1, 0, 1, 7, 2**31 - 1, -(2**31), nearby))
            cut = damaged[: rng.randrange(len(damaged) + 1)]
            for candidate in (damaged, cut):
                raw = b"".join(value.to_bytes(4, "little", signed=True) for value in candidate)
                try:
                    encoder = native.Encoder(raw)
                except ValueError:
                    continue
                encoder.to_pb(b"\x00\x01\x00\x00" + bytes(64))  # loaded: runs without harm

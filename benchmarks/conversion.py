"""Per-message conversion cost (issue 4), in this process, with the bridge's allocator tuning.

Usage: ``.venv/bin/python -m benchmarks.conversion [--seconds S]``; writes the report
``benchmarks/reports/conversion.md``. ROS->GZ is what a channel does per message: the
registry's ``to_gz`` plus ``SerializeToString``; GZ->ROS is ``FromString`` plus ``to_ros``.
rclpy's own CDR
(de)serialization, which ``publish`` and the subscription do on top, is shown beside it. The
ceiling is one copy of the serialized message (``bytes(bytearray(payload))``), measured here.
"""

from __future__ import annotations

import argparse
import dataclasses
import statistics
import sys
import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from benchmarks.payloads import KINDS, gz_message
from benchmarks.report import write_section
from ros_gz_bridge_py.bulk.path import BulkPath, gz_to_ros_cdr, ros_cdr_to_gz
from ros_gz_bridge_py.bulk.protowire import split_bytes_field
from ros_gz_bridge_py.msgs import message_class
from ros_gz_bridge_py.ros import light_reader
from ros_gz_bridge_py.ros.runtime import tune_allocator

CASES = ("image640", "image1080", "cloud1mb", "scan1440", "tf50", "tf20", "odometry", "twist")
#: Goal per message and direction, ms (issue 4).
GOAL_MS = {"image1080": 1.0}
DEFAULT_GOAL_MS = 0.5


def timing(operation: Callable[[], object], seconds: float) -> tuple[float, float]:
    """(median, min) milliseconds of ``operation`` over ``seconds`` (at least 20 runs)."""
    for _ in range(3):
        operation()
    times: list[float] = []
    end = time.perf_counter() + seconds
    while len(times) < 20 or time.perf_counter() < end:
        start = time.perf_counter()
        operation()
        times.append((time.perf_counter() - start) * 1000)
    return statistics.median(times), min(times)


@dataclass(frozen=True)
class Measured:
    kind: str
    size: int
    to_gz: tuple[float, float]
    to_ros: tuple[float, float]
    serialize_cdr: tuple[float, float]
    deserialize_cdr: tuple[float, float]
    copy: tuple[float, float]
    #: The bulk path (Image, PointCloud2): received CDR -> gz payload, gz payload -> CDR.
    bulk_to_gz: tuple[float, float] | None = None
    bulk_to_ros: tuple[float, float] | None = None
    #: The other ROS->GZ channels: received CDR read by ros_cdr, to_gz, SerializeToString.
    light_to_gz: tuple[float, float] | None = None

    def channel_cost(self) -> tuple[tuple[str, float], tuple[str, float]]:
        """(label, median ms) per direction of what a channel does per message."""
        if self.bulk_to_gz is not None and self.bulk_to_ros is not None:
            return ("ROS->GZ (bulk path)", self.bulk_to_gz[0]), (
                "GZ->ROS (bulk path)",
                self.bulk_to_ros[0],
            )
        if self.light_to_gz is not None:
            return ("ROS->GZ (light read)", self.light_to_gz[0]), ("GZ->ROS", self.to_ros[0])
        return ("ROS->GZ", self.to_gz[0]), ("GZ->ROS", self.to_ros[0])


def measure(name: str, seconds: float) -> Measured:
    from rclpy.serialization import deserialize_message, serialize_message  # noqa: PLC0415

    kind = KINDS[name]
    pair = kind.pair
    ros_msg = kind.make_ros()
    payload: bytes = gz_message(kind).SerializeToString()
    parse = message_class(kind.gz_type).FromString
    cdr = serialize_message(ros_msg)

    def to_gz() -> Any:
        return pair.to_gz(ros_msg).SerializeToString()

    def to_ros() -> Any:
        return pair.to_ros(parse(payload))

    measured = Measured(
        name,
        len(payload),
        timing(to_gz, seconds),
        timing(to_ros, seconds),
        timing(lambda: serialize_message(ros_msg), seconds),
        timing(lambda: deserialize_message(cdr, pair.ros_class), seconds),
        timing(lambda: bytes(bytearray(payload)), seconds),
    )
    bulk = pair.bulk
    if bulk is None:
        if light_reader.reader_for(pair.ros_class) is None:
            return measured

        def light_to_gz() -> Any:
            return pair.to_gz(light_reader.read(cdr, pair.ros_class)).SerializeToString()

        return dataclasses.replace(measured, light_to_gz=timing(light_to_gz, seconds))
    gz_class = message_class(kind.gz_type)
    return dataclasses.replace(
        measured,
        bulk_to_gz=timing(lambda: ros_cdr_to_gz(bulk, pair.ros_class, cdr), seconds),
        bulk_to_ros=timing(in_frame(bulk, gz_class, payload), seconds),
    )


def in_frame(bulk: BulkPath, gz_class: type[Any], payload: bytes) -> Callable[[], Any]:
    """The bulk path's Gazebo -> ROS conversion of ``payload`` as a channel gets it: in a
    writable frame of its own (a received ZeroMQ frame), where the CDR is written around the
    data when the frame has room. The bytes around the data are put back after each call (a
    few dozen; the data is never written), so every call converts the same frame."""
    frame = memoryview(bytearray(payload))
    _, at, length = split_bytes_field(frame, bulk.gz_field)
    head, tail = payload[:at], payload[at + length :]

    def convert() -> Any:
        cdr = gz_to_ros_cdr(bulk, gz_class, frame)
        frame[:at] = head
        frame[at + length :] = tail
        return cdr

    return convert


def _size(size: int) -> str:
    return f"{size / 1e6:.2f} MB" if size >= 100_000 else f"{size / 1e3:.1f} kB"


LABELS = {
    "image640": "640x480 rgb8 Image",
    "image1080": "1920x1080 rgb8 Image",
    "cloud1mb": "1 MB PointCloud2",
    "scan1440": "1440-ray LaserScan",
    "tf50": "50-transform TFMessage",
    "tf20": "20-transform TFMessage",
    "odometry": "Odometry",
    "twist": "Twist",
}


def _cell(value: tuple[float, float] | None) -> str:
    return "-" if value is None else f"{value[0]:.3f} ({value[1]:.3f})"


def row(m: Measured) -> str:
    return (
        f"| {LABELS[m.kind]} | {_size(m.size)} | {_cell(m.to_gz)} | {_cell(m.to_ros)} "
        f"| {m.copy[0]:.3f} | {max(m.to_gz[0], m.to_ros[0]) / max(m.copy[0], 1e-6):.1f}x "
        f"| {m.serialize_cdr[0]:.3f} | {m.deserialize_cdr[0]:.3f} "
        f"| {_cell(m.bulk_to_gz)} | {_cell(m.bulk_to_ros)} | {_cell(m.light_to_gz)} |"
    )


#: Above this many copies' worth of time, per-field Python work (not bytes) sets the cost.
PER_FIELD_RATIO = 20.0


def bound(m: Measured, median: float) -> str:
    """What a missed conversion spends its time on, judged against one payload copy."""
    copies = median / max(m.copy[0], 1e-6)
    if copies > PER_FIELD_RATIO:
        return f" (bound by per-field Python work; the payload copies in {m.copy[0]:.3f} ms)"
    return (
        f" (bound by whole-payload copies: {copies:.1f} copies' worth at {m.copy[0]:.3f} ms each)"
    )


def goal(m: Measured) -> str:
    limit = GOAL_MS.get(m.kind, DEFAULT_GOAL_MS)
    parts = []
    for direction, median in m.channel_cost():
        verdict = "**met**" if median < limit else f"**missed** by {median - limit:.3f} ms"
        parts.append(
            f"{direction} {median:.3f} ms — {verdict}{'' if median < limit else bound(m, median)}"
        )
    return f"- {LABELS[m.kind]} < {limit:g} ms each way: {'; '.join(parts)}"


TABLE_HEADER = (
    "| message | protobuf size | ROS->GZ ms | GZ->ROS ms | ceiling (copy) ms | x ceiling "
    "| rclpy serialize ms | rclpy deserialize ms | bulk ROS->GZ ms | bulk GZ->ROS ms "
    "| light-read ROS->GZ ms |\n"
    "|---|---|---|---|---|---|---|---|---|---|---|"
)


def markdown(results: list[Measured], seconds: float) -> str:
    rows = "\n".join(row(m) for m in results)
    return f"""## Conversion cost per message (issue 4)

Command: `.venv/bin/python -m benchmarks.conversion --seconds {seconds:g}`

One process (the bridge's converters; one core, 100% busy while measuring), glibc allocator
tuned as in the bridge. Milliseconds, median (min) over >= {seconds:g} s per cell. ROS->GZ =
registry `to_gz` + protobuf `SerializeToString`; GZ->ROS = protobuf `FromString` + `to_ros`.
Ceiling: one copy of the serialized message, measured in the same run ("x ceiling" = the
slower direction / the copy). rclpy's CDR columns are what `publish()` / a subscription add
on the object path. The bulk columns are what Image and PointCloud2 channels do instead (see
README "Architecture", `bulk/`): received CDR bytes -> Gazebo payload (one copy of the
data), and a received frame -> CDR bytes ready for `rcl_publish_serialized_message` (written
in the frame around the data where it has room, as a Gazebo camera's frame with its header's
`seq` has, no copy; else one copy); they already include the (de)serialization, so they
compare with ROS->GZ + deserialize and GZ->ROS + serialize. The light-read column is what
the other ROS->GZ channels do: the received CDR read by `ros_cdr` into attribute trees (no
rclpy message objects), `to_gz`, `SerializeToString`; it compares with ROS->GZ +
deserialize. The goals are judged on what the channels do.

{TABLE_HEADER}
{rows}

Goals (1080p image < 1 ms each way, the others < 0.5 ms):
{chr(10).join(goal(m) for m in results)}
"""


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--seconds", type=float, default=1.0, help="time per measurement")
    args = parser.parse_args(argv)
    tune_allocator()
    results = [measure(name, args.seconds) for name in CASES]
    for m in results:
        print(row(m), file=sys.stderr)
    write_section("conversion", markdown(results, args.seconds))
    return 0


if __name__ == "__main__":
    sys.exit(main())

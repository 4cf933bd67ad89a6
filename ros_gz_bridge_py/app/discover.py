"""``parameter_bridge --discover [SECONDS]``: the YAML of what discovered bridging would bridge.

It listens to Gazebo discovery for a few seconds, plans as ``auto_bridge`` would
(``core/discovery_plan.py``: the allow and deny patterns, the name rule, the YAML entries that
discovery completes, explicit entries left out) and prints a YAML file on standard output, one
entry per topic, for the user to edit and commit. Logs go to standard error, so
``parameter_bridge --discover > bridge.yaml`` writes a file ``config_file`` takes as it is.
Entries whose types were inferred from a ROS publisher (the Gazebo subscribers told none) carry
a comment that says so: the Gazebo side was not seen to take that type. SIGINT or SIGTERM end
the listening at once; the YAML then holds what was heard until then.
"""

from __future__ import annotations

import json
import time
from collections.abc import Sequence
from typing import TextIO

from ros_gz_bridge_py.config import Direction, TopicBridgeSpec
from ros_gz_bridge_py.core.discovery_plan import BY_ROS_PUBLISHER
from ros_gz_bridge_py.msgs.names import canonical_type
from ros_gz_bridge_py.ros.stop_signal import StopSignal

#: Seconds ``--discover`` listens by default: every peer re-announces within a second, and
#: discovery counts as complete after two (docs/protocol-zmq-discovery.md §2.5).
DEFAULT_SECONDS = 5.0
#: Longest wait between two looks at the stop request: SIGINT and SIGTERM end within it.
_STEP = 0.1

#: Comments on the QoS of some ROS types and names, written above their entries.
_HINTS_BY_NAME = {
    "clock": "# /clock: rclcpp's time source subscribes best effort, which this reliable "
    "publisher serves; keep one bridge of /clock per simulation",
    "tf_static": "# /tf_static is published transient-local: TF listeners that start "
    "later still get the static transforms",
}
_SENSOR_TYPES = frozenset(
    {"sensor_msgs/msg/Image", "sensor_msgs/msg/PointCloud2", "sensor_msgs/msg/LaserScan"}
)
_SENSOR_HINT = (
    "# a sensor stream: max_rate: <Hz> drops messages before conversion, qos_profile: "
    "SENSOR_DATA matches best-effort subscribers"
)


def listen(seconds: float, spin_once: object = None, stop: StopSignal | None = None) -> bool:
    """Wait ``seconds`` (spinning ROS with ``spin_once(timeout_sec=...)`` when given), or less
    when ``stop`` (the executable's SIGINT and SIGTERM) is requested: False then."""
    deadline = time.monotonic() + seconds
    while (remaining := deadline - time.monotonic()) > 0:
        if stop is not None and stop.requested:
            return False
        if callable(spin_once):
            spin_once(timeout_sec=min(_STEP, remaining))
        else:
            time.sleep(min(_STEP, remaining))
    return stop is None or not stop.requested


def write_yaml(specs: Sequence[TopicBridgeSpec], header: Sequence[str], out: TextIO) -> None:
    """The entries of ``specs`` as a bridge YAML file, preceded by ``header`` comments."""
    for line in header:
        print(f"# {line}", file=out)
    if not specs:
        print("[]", file=out)
        return
    for spec in specs:
        for hint in _hints(spec):
            print(hint, file=out)
        print(f"- ros_topic_name: {_quoted(spec.ros_topic)}", file=out)
        print(f"  gz_topic_name: {_quoted(spec.gz_topic)}", file=out)
        print(f"  ros_type_name: {_quoted(spec.ros_type)}", file=out)
        print(f"  gz_type_name: {_quoted(canonical_type(spec.gz_type))}", file=out)
        print(f"  direction: {spec.direction.value}", file=out)
        optional = {
            "lazy": None if spec.lazy is None else str(spec.lazy).lower(),
            "publisher_queue": spec.publisher_queue,
            "subscriber_queue": spec.subscriber_queue,
            "qos_profile": spec.qos_profile,
            "frame_id": None if spec.frame_id is None else _quoted(spec.frame_id),
            "max_rate": spec.max_rate,
        }
        for key, value in optional.items():
            if value is not None:
                print(f"  {key}: {value}", file=out)


def header_lines(
    seconds: float, listening: str, count: int, specs: Sequence[TopicBridgeSpec] = ()
) -> list[str]:
    """What the file is and how its names and types are written (``specs``: its entries)."""
    lines = [
        f"Written by parameter_bridge --discover {seconds:g}: {count} Gazebo topics seen by",
        f"{listening}.",
        "Gazebo types are written gz.msgs.X; they also match ignition.msgs.X (Fortress) peers.",
        "Relative ROS names resolve in the bridge's namespace (/ unless -r __ns:=... is given).",
        "Use: parameter_bridge --ros-args -p config_file:=<this file>",
    ]
    inferred = sum(1 for spec in specs if spec.discovered_by == BY_ROS_PUBLISHER)
    if inferred:
        lines.append(
            f"{inferred} entries (marked 'inferred') take their types from the ROS publisher: "
            "their Gazebo subscribers tell no type."
        )
    return lines


def _hints(spec: TopicBridgeSpec) -> list[str]:
    hints = []
    if spec.discovered_by == BY_ROS_PUBLISHER:
        hints.append(
            f"# inferred: {spec.gz_topic}'s Gazebo subscribers tell no type (gz-transport 11/12); "
            f"the types are the ROS publisher's ({spec.ros_type}) and its default Gazebo type"
        )
    name = spec.ros_topic.strip("/")
    if name in _HINTS_BY_NAME:
        hints.append(_HINTS_BY_NAME[name])
    if spec.ros_type in _SENSOR_TYPES and spec.direction is Direction.GZ_TO_ROS:
        hints.append(_SENSOR_HINT)
    return hints


def _quoted(text: str) -> str:
    """A YAML double-quoted scalar (JSON strings are valid YAML)."""
    return json.dumps(text)

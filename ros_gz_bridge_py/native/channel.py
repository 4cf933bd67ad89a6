"""Which channels take the native path, and with which programs (docs/native.md §1, §6).

A Gazebo -> ROS channel takes it when the extension is built and may be used (the bridge's
``native`` option, ``ROS_GZ_BRIDGE_NATIVE``), its backend lets a native loop read (ZeroMQ),
it publishes serialized messages through rcl (the ``cdr_write`` and ``rcl_serialized_publish``
options), and a program compiles for at least one spelling of its Gazebo type. Programs are
compiled once per pair and shared: they are read-only once loaded.
"""

from __future__ import annotations

import functools
import logging
from collections.abc import Iterable
from typing import TYPE_CHECKING, Any

from ros_gz_bridge_py.converters.registry import Pair
from ros_gz_bridge_py.native import extension, unavailable_reason
from ros_gz_bridge_py.native.abi import zmq_functions, zmq_layout_fits
from ros_gz_bridge_py.native.encoder import compile_to_gz
from ros_gz_bridge_py.native.program import compile_to_ros
from ros_gz_bridge_py.native.words import NotExpressibleError

if TYPE_CHECKING:
    from ros_gz_bridge_py.native._native import Encoder, Program

_LOG = logging.getLogger("ros_gz_bridge_py.native")


Reasons = dict[tuple[str, str], str]


def expressible(pairs: Iterable[Pair]) -> tuple[Reasons, Reasons]:
    """Per (ROS type, Gazebo type), for each direction (to ROS, to Gazebo): "" where a native
    program compiles, else why not."""
    to_ros: Reasons = {}
    to_gz: Reasons = {}
    for pair in pairs:
        key = (pair.ros_type, pair.gz_type)
        for found, compile_one in ((to_ros, compile_to_ros), (to_gz, compile_to_gz)):
            try:
                compile_one(pair)
                found[key] = ""
            except NotExpressibleError as err:
                found[key] = str(err)
    return to_ros, to_gz


def native_programs(
    layouts: dict[str, Pair], options: Any, gz_node: Any, *, frame_id: str = ""
) -> dict[str, Program]:
    """The program of each wire spelling a channel of ``layouts`` runs natively (``frame_id``:
    the channel's header rewrite); empty when the channel takes the Python path."""
    if not (options.native and options.cdr_write and options.rcl_serialized_publish):
        return {}
    if not gz_node.runs_native_loops or not native_path_available():
        return {}
    stamp = bool(options.override_timestamps_with_wall_time)
    programs = {wire_type: program_of(pair, frame_id, stamp) for wire_type, pair in layouts.items()}
    return {wire_type: program for wire_type, program in programs.items() if program is not None}


@functools.cache
def _extension_available() -> bool:
    """Whether the extension is built; logged once where not."""
    if extension() is None:
        _LOG.warning("Every channel takes the Python path: %s", unavailable_reason())
        return False
    return True


@functools.cache
def native_path_available() -> bool:
    """Whether the extension and the functions it calls are there, and libzmq lays out its
    messages as the loop declares (native/abi.py); logged once where not."""
    return _extension_available() and zmq_functions() is not None and zmq_layout_fits()


@functools.cache
def program_of(pair: Pair, frame_id: str = "", wall_stamp: bool = False) -> Program | None:
    """The loaded program of ``pair`` with a header rewrite (compiled once), or None where it
    stays on Python."""
    native = extension()
    if native is None:
        return None
    try:
        compiled = compile_to_ros(pair, frame_id=frame_id, wall_stamp=wall_stamp)
    except NotExpressibleError:
        return None
    return native.Program(compiled.schema, compiled.ops)


def native_encoders(layouts: dict[str, Pair], options: Any) -> dict[str, Encoder]:
    """The encoder of each wire spelling a ROS -> Gazebo channel of ``layouts`` runs natively
    (docs/native.md §6); empty where the channel converts in Python."""
    if not (options.native and options.light_read) or not _extension_available():
        return {}
    encoders = {wire_type: encoder_of(pair) for wire_type, pair in layouts.items()}
    found = {wire_type: encoder for wire_type, encoder in encoders.items() if encoder is not None}
    return found if len(found) == len(encoders) else {}


@functools.cache
def encoder_of(pair: Pair) -> Encoder | None:
    """The loaded ROS -> Gazebo encoder of ``pair`` (compiled once), or None."""
    native = extension()
    if native is None:
        return None
    try:
        words = compile_to_gz(pair)
    except NotExpressibleError:
        return None
    return native.Encoder(words)

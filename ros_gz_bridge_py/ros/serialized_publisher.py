"""Publish serialized (CDR) messages through rcl with the GIL released, and message objects
serialized by :mod:`.cdr_writer`.

rclpy's ``Publisher.publish`` holds the GIL for the whole DDS write, which for a 6 MB image is
milliseconds during which no other Python thread of the bridge runs (``/clock`` starves).
``rcl_publish_serialized_message`` called through :mod:`ctypes` releases the GIL for the call,
like any ctypes foreign call. The rcl publisher is the one rclpy created (``handle.pointer``),
kept alive during the call by entering its handle. When librcl cannot be loaded this way, or
the caller asks for it (the bridge's ``rcl_serialized_publish`` option; the executables'
``ROS_GZ_BRIDGE_SERIALIZED_PUBLISH=rclpy``), publishing goes through rclpy's own serialized
publish instead (same bytes on the wire, GIL held).
"""

from __future__ import annotations

import ctypes
import functools
from dataclasses import dataclass
from typing import Any

from ros_gz_bridge_py.errors import BridgeError
from ros_gz_bridge_py.ros.cdr_writer import Writer, writer_for

#: rcl's return code for success.
_RCL_RET_OK = 0


class _SerializedMessage(ctypes.Structure):
    """rcl_serialized_message_t (rcutils_uint8_array_t): buffer, length, capacity, allocator.

    ``buffer`` given a ``bytes`` object points into it (no copy) and keeps it alive.
    """

    _fields_ = (
        ("buffer", ctypes.c_char_p),
        ("buffer_length", ctypes.c_size_t),
        ("buffer_capacity", ctypes.c_size_t),
        ("allocator", ctypes.c_void_p * 5),
    )


@dataclass(frozen=True)
class _Rcl:
    publish_serialized: Any
    reset_error: Any


@functools.cache
def _rcl() -> _Rcl | None:
    """The rcl functions from the librcl rclpy already loaded, or None."""
    try:
        publish = ctypes.CDLL("librcl.so").rcl_publish_serialized_message
        reset_error = ctypes.CDLL("librcutils.so").rcutils_reset_error
    except (OSError, AttributeError):
        return None
    publish.argtypes = (ctypes.c_void_p, ctypes.POINTER(_SerializedMessage), ctypes.c_void_p)
    publish.restype = ctypes.c_int32
    reset_error.argtypes = ()
    reset_error.restype = None
    return _Rcl(publish, reset_error)


def _buffer(cdr: bytes | memoryview) -> bytes | int:
    """What ``_SerializedMessage.buffer`` takes for ``cdr``: bytes as they are, a read-only
    view as a copy, a writable view's address (its memory lives as long as the view, which
    ``publish``'s caller holds)."""
    if isinstance(cdr, bytes):
        return cdr
    if cdr.readonly:
        return bytes(cdr)
    return ctypes.addressof(ctypes.c_char.from_buffer(cdr))


class SerializedPublisher:
    """Publishes CDR bytes (with their encapsulation header) on an rclpy publisher.

    ``through_rcl``: write through rcl with the GIL released when librcl can be loaded; False
    publishes through rclpy.
    """

    def __init__(self, publisher: Any, *, through_rcl: bool) -> None:
        self._publisher = publisher
        self._handle = publisher.handle
        self._pointer: int = publisher.handle.pointer
        self._rcl = _rcl() if through_rcl else None

    def publish(self, cdr: bytes | memoryview) -> None:
        """Publish one serialized message; ``cdr`` is not copied before rcl takes it (a
        read-only view is, and every view on the rclpy way: rclpy publishes bytes only)."""
        if self._rcl is None:
            self._publisher.publish(cdr if isinstance(cdr, bytes) else bytes(cdr))
            return
        message = _SerializedMessage(_buffer(cdr), len(cdr), len(cdr))
        with self._handle:
            ret = self._rcl.publish_serialized(self._pointer, ctypes.byref(message), None)
        if ret != _RCL_RET_OK:
            self._rcl.reset_error()
            msg = f"rcl_publish_serialized_message failed on {self._publisher.topic_name} ({ret})"
            raise BridgeError(msg)


class WrittenPublisher:
    """Publishes message objects as CDR from a compiled :mod:`.cdr_writer` writer.

    A message the writer refuses (it raises for any value it cannot write exactly as rclpy
    would) goes through rclpy's ``publish`` instead, which publishes or refuses it as it always
    did; ``fallbacks`` counts them. Both ways use the same rcl publisher, so publication
    sequence numbers stay in step (the loop guard relies on them).
    """

    def __init__(self, publisher: Any, writer: Writer, *, through_rcl: bool) -> None:
        self._serialized = SerializedPublisher(publisher, through_rcl=through_rcl)
        self._writer = writer
        self._publish_object = publisher.publish
        self.fallbacks = 0

    def publish(self, msg: Any) -> bytes | None:
        """Publish ``msg``; the CDR bytes written, or None when rclpy wrote it (the loop
        guard keeps them to know the sample when it comes back, ``core/loop_guard.py``)."""
        try:
            cdr = self._writer(msg)
        except Exception:  # any refusal: rclpy decides
            self.fallbacks += 1
            self._publish_object(msg)
            return None
        self._serialized.publish(cdr)
        return cdr


def object_publisher(publisher: Any, msg_class: type[Any], *, through_rcl: bool) -> Any:
    """What publishes ``msg_class`` objects on ``publisher`` the fastest way: a
    :class:`WrittenPublisher` where a writer compiles, else ``publisher`` itself."""
    writer = writer_for(msg_class)
    if writer is None:
        return publisher
    return WrittenPublisher(publisher, writer, through_rcl=through_rcl)

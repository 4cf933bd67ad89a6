"""Publish serialized (CDR) messages through rcl with the GIL released.

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

#: rcl's return code for success.
_RCL_RET_OK = 0


class _SerializedMessage(ctypes.Structure):
    """rcl_serialized_message_t (rcutils_uint8_array_t): buffer, length, capacity, allocator."""

    _fields_ = (
        ("buffer", ctypes.c_void_p),
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

    def publish(self, cdr: bytes) -> None:
        """Publish one serialized message; ``cdr`` is not copied before rcl takes it."""
        if self._rcl is None:
            self._publisher.publish(cdr)
            return
        address = ctypes.cast(ctypes.c_char_p(cdr), ctypes.c_void_p).value
        message = _SerializedMessage(address, len(cdr), len(cdr))
        with self._handle:
            ret = self._rcl.publish_serialized(self._pointer, ctypes.byref(message), None)
        if ret != _RCL_RET_OK:
            self._rcl.reset_error()
            msg = f"rcl_publish_serialized_message failed on {self._publisher.topic_name} ({ret})"
            raise BridgeError(msg)

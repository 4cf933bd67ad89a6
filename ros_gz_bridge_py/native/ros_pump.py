"""The native input of one ROS -> Gazebo channel, served by the shared loop (docs/native.md §7).

:class:`RosChannelPump` holds the C ``RosPump`` (ros_pump.c) of one channel's input: the rclpy
subscription it takes from (on a node no executor spins, so nothing else takes its messages),
the channel's Gazebo publisher with a PUB socket of its own (only the loop's thread sends on
it), and the encoder of each spelling. The process's one loop (ros_loop.py) runs it; the
pump tells that loop when the spellings Gazebo subscribers take or the bridge's own publishers
on the topic change, and the loop's thread calls back, between C runs, to sync them, to count
and to hand over the messages an encoder left to the Python path.
"""

from __future__ import annotations

import contextlib
import ctypes
import functools
import logging
import threading
from collections.abc import Callable, Mapping
from typing import Any

import zmq

from ros_gz_bridge_py.native import extension
from ros_gz_bridge_py.native.pump import libzmq_path, loaded_libraries
from ros_gz_bridge_py.native.ros_loop import shared_loop

_LOG = logging.getLogger("ros_gz_bridge_py.native")


@functools.cache
def ros_functions() -> tuple[int, ...] | None:
    """The addresses of the rcl, rmw, rcutils and libzmq functions the loop calls, or None."""
    path, rmw = libzmq_path(), _rmw_library()
    if path is None or rmw is None:
        return None
    try:
        rcl, rcutils, libzmq = (
            ctypes.CDLL("librcl.so"),
            ctypes.CDLL("librcutils.so"),
            ctypes.CDLL(path),
        )
        functions = (
            rcl.rcl_take_serialized_message,
            rcl.rcl_subscription_set_on_new_message_callback,
            rcutils.rcutils_reset_error,
            rcutils.rcutils_get_default_allocator,
            rcl.rcl_publisher_get_rmw_handle,
            rmw.rmw_get_gid_for_publisher,
            libzmq.zmq_send,
        )
    except (OSError, AttributeError) as err:
        _LOG.warning(
            "ROS -> Gazebo channels convert in Python: rcl cannot be used from C (%s)", err
        )
        return None
    addresses = tuple(ctypes.cast(function, ctypes.c_void_p).value or 0 for function in functions)
    return addresses if all(addresses) else None


def _rmw_library() -> Any:
    """The loaded rmw library that has ``rmw_get_gid_for_publisher``: rmw_implementation's
    dispatcher where rcl goes through it (a ROS install), else the implementation rcl is
    linked with (the PyPI wheels link rmw_fastrtps_cpp)."""
    candidates = [path for path in loaded_libraries() if "/librmw" in path]
    candidates.sort(key=lambda path: "rmw_implementation" not in path)
    for candidate in candidates:
        with contextlib.suppress(OSError, AttributeError):
            library = ctypes.CDLL(candidate)
            library.rmw_get_gid_for_publisher  # noqa: B018 - does it have the function?
            return library
    _LOG.warning("ROS -> Gazebo channels convert in Python: no loaded rmw library gives GIDs")
    return None


class RosChannelPump:
    """The native input of one ROS -> Gazebo channel (see the module docstring).

    ``refused(cdr)``: the channel's Python path for one admitted message;
    ``counted(received, own_skipped, rate_limited, published, send_failures)``: what the loop
    did since it last said; ``lost(count)``: messages for the Python path that could not be
    copied (no memory) since it last said; ``failed(reason)``: the channel's socket failed
    and the loop took the channel off (nothing more is taken); ``own_publishers()``: the rcl
    publishers of the bridge on the topic, and ``watch_own_publishers(changed)`` calls
    ``changed()`` when they change (it returns the function that stops it). The publisher's
    ``watch_wire_types`` does the same for the spellings. Every callback runs on the loop's
    thread. Closing the publisher (or its node) first takes the channel off the loop.
    """

    def __init__(
        self,
        *,
        subscription: Any,
        publisher: Any,
        encoders: Mapping[str, Any],
        max_rate: float,
        refused: Callable[[bytes], None],
        counted: Callable[[int, int, int, int, int], None],
        lost: Callable[[int], None],
        failed: Callable[[str], None],
        own_publishers: Callable[[], frozenset[int]],
        watch_own_publishers: Callable[[Callable[[], None]], Callable[[], None]],
        name: str,
    ) -> None:
        native, functions = extension(), ros_functions()
        if native is None or functions is None:
            msg = "no native extension or foreign functions"
            raise RuntimeError(msg)
        order = [publisher.msg_type, *(t for t in encoders if t != publisher.msg_type)]
        spellings = []
        for wire_type in order:
            topic, sender, _payload, type_frame = publisher.wire_frames[wire_type]
            spellings.append((type_frame, topic, sender, encoders[wire_type]))
        self.name = name
        self._subscription = subscription
        self._publisher = publisher
        self.pump = native.RosPump(
            functions, subscription.handle.pointer, publisher.sock.underlying, spellings, max_rate
        )
        self._refused = refused
        self._counted = counted
        self._lost = lost
        self._failed = failed
        self._own_publishers = own_publishers
        self._seen = (0, 0, 0, 0, 0, 0)
        self._active: frozenset[str] | None = None
        self._ignored: frozenset[int] | None = None
        self._closed = False
        self._close_lock = threading.Lock()
        self._loop = shared_loop()
        self._unwatch = (
            publisher.watch_wire_types(self.wake),
            watch_own_publishers(self.wake),
            publisher.before_close(self.close),
        )
        # In use while attached: a destroy meanwhile (rclpy's) waits for close.
        self._in_use = contextlib.ExitStack()
        self._in_use.enter_context(subscription.handle)
        self.sync()  # before the loop takes a message: a subscriber's spelling is not missed
        try:
            self._loop.attach(self)
        except Exception:
            self._in_use.close()
            for unwatch in self._unwatch:
                unwatch()
            raise

    def __repr__(self) -> str:
        return f"<native ROS -> Gazebo channel {self.name}>"

    def wake(self) -> None:
        """Have the loop read the spellings and own publishers again soon (any thread; quick;
        nothing after :meth:`close`)."""
        if not self._closed:
            self._loop.wake(self)

    def close(self) -> None:
        """Take the channel off the loop and stop rcl's callback; idempotent. The
        subscription and the publisher's socket may go after: a second caller (the channel
        and the node's close at once) returns only when the first is done."""
        with self._close_lock:
            if self._closed:
                return
            self._closed = True
            for unwatch in self._unwatch:
                unwatch()
            self._loop.detach(self)
            self._in_use.close()

    def sync(self) -> None:
        """Tell the C side the spellings subscribers take and the publishers to skip."""
        active = self._publisher.wire_types()
        if active != self._active:
            self.pump.set_active({name.encode() for name in active})
            self._active = active
        ignored = self._own_publishers()
        if ignored != self._ignored:
            self.pump.ignore(sorted(ignored))
            self._ignored = ignored

    def turn(self, refused: list[bytes], failure: int) -> None:
        """The loop says the channel moved: the messages left to Python, the counters, and
        the failure of its socket (an errno of libzmq, 0 if none)."""
        for cdr in refused:
            self._refused(cdr)
        received, own_skipped, rate_limited, published, _take_errors, send_failures, lost = (
            self.pump.counts()
        )
        now = (received, own_skipped, rate_limited, published, send_failures, lost)
        before, self._seen = self._seen, now
        *deltas, lost_now = (a - b for a, b in zip(now, before, strict=True))
        if any(deltas):
            self._counted(*deltas)
        if lost_now:
            self._lost(lost_now)
        self.sync()  # a channel that moved has subscribers: a cheap safety net for them
        if failure:
            self._failed(
                f"its Gazebo socket failed ({zmq.strerror(failure)}); the channel takes no "
                "more ROS messages (restart the bridge)"
            )
            # Off the loop now; the rest when the channel closes. Not close(): a close
            # waiting for this turn on another thread holds its lock.
            self._loop.detach(self)

"""A native ROS -> Gazebo channel's loop and the thread that runs it (docs/native.md §7).

:class:`RosChannelPump` holds the C ``RosPump`` (ros_pump.c) of one channel's input: the rclpy
subscription it takes from (on a node no executor spins, so nothing else takes its messages),
the channel's Gazebo publisher with a PUB socket of its own (only this thread sends on it), and
the encoder of each spelling. Its thread runs the C loop with the GIL released and, between
runs, does in Python what changes slowly: the spellings Gazebo subscribers take now, the
bridge's own publishers on the topic (the loop guard), the counters, and the messages an
encoder left to the Python path. A run returns with the messages left to Python, when
:meth:`RosChannelPump.wake` is called (the channel calls it when the spellings or its own
publishers change), and otherwise after :data:`TURN` seconds, or :data:`QUIET_TURN` after a
run that took no message (nothing to count).
"""

from __future__ import annotations

import contextlib
import ctypes
import functools
import logging
import socket
import threading
import time
from collections.abc import Callable, Mapping
from typing import Any

from ros_gz_bridge_py.native import extension
from ros_gz_bridge_py.native.pump import libzmq_path, loaded_libraries

_LOG = logging.getLogger("ros_gz_bridge_py.native")
#: Longest time (s) between two turns of the Python side of the loop while messages come.
TURN = 0.25
#: The same after a run that took no message. Changes are pushed (:meth:`RosChannelPump.wake`),
#: so this is only a safety net; 66 idle loops turning every :data:`TURN` cost an idle bridge
#: of 66 bidirectional entries 2.5 points of a core (docs/native.md §7).
QUIET_TURN = 2.0


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
    ``counted(received, own_skipped, rate_limited, published)``: what the loop did since it
    last said; ``own_publishers()``: the rcl publishers of the bridge on the topic, and
    ``watch_own_publishers(changed)`` calls ``changed()`` when they change (it returns the
    function that stops it). The publisher's ``watch_wire_types`` does the same for the
    spellings.
    """

    def __init__(
        self,
        *,
        subscription: Any,
        publisher: Any,
        encoders: Mapping[str, Any],
        max_rate: float,
        refused: Callable[[bytes], None],
        counted: Callable[[int, int, int, int], None],
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
        self._subscription = subscription
        self._publisher = publisher
        self._pump = native.RosPump(
            functions, subscription.handle.pointer, publisher.sock.underlying, spellings, max_rate
        )
        self._refused = refused
        self._counted = counted
        self._own_publishers = own_publishers
        self._seen = (0, 0, 0, 0)
        self._active: frozenset[str] | None = None
        self._ignored: frozenset[int] | None = None
        self._closed = False
        self._wake_r, self._wake_w = socket.socketpair()
        self._wake_r.setblocking(False)
        self._wake_w.setblocking(False)
        self._pump.start()
        self._unwatch = (publisher.watch_wire_types(self.wake), watch_own_publishers(self.wake))
        self._thread = threading.Thread(target=self._run, name=f"ros-pub {name}", daemon=True)
        self._thread.start()

    def wake(self) -> None:
        """End the current run soon, so the loop reads the spellings and own publishers again
        (any thread; quick; nothing after :meth:`close`)."""
        with contextlib.suppress(OSError):  # a wake already pending, or closed
            self._wake_w.send(b"\0")

    def close(self) -> None:
        """Stop the thread and rcl's callback; idempotent. The subscription may go after."""
        if self._closed:
            return
        self._closed = True
        for unwatch in self._unwatch:
            unwatch()
        self.wake()
        if self._thread is not threading.current_thread():
            self._thread.join()
        self._pump.stop()
        self._wake_r.close()
        self._wake_w.close()

    def _run(self) -> None:
        took = True
        while not self._closed:
            try:
                self._sync()
                timeout = int((TURN if took else QUIET_TURN) * 1000)
                with self._subscription.handle:
                    _events, refused = self._pump.run(self._wake_r.fileno(), timeout)
                with contextlib.suppress(BlockingIOError):
                    self._wake_r.recv(4096)
                for cdr in refused:
                    self._refused(cdr)
                took = self._count()
            except Exception:  # the loop must outlive anything, as the readers do
                _LOG.exception("unexpected error in the native loop of %s", self._publisher.topic)
                time.sleep(TURN)  # and not spin on an error that stays

    def _sync(self) -> None:
        """Tell the C loop the spellings subscribers take and the publishers to skip."""
        active = self._publisher.wire_types()
        if active != self._active:
            self._pump.set_active({name.encode() for name in active})
            self._active = active
        ignored = self._own_publishers()
        if ignored != self._ignored:
            self._pump.ignore(sorted(ignored))
            self._ignored = ignored

    def _count(self) -> bool:
        """Tell the channel what the loop did since the last turn; True if it took a message."""
        now = self._pump.counts()[:4]
        before, self._seen = self._seen, now
        deltas = tuple(a - b for a, b in zip(now, before, strict=True))
        if any(deltas):
            self._counted(*deltas)
        return bool(deltas[0])

"""A native Gazebo -> ROS channel's pump, as its reader and its channel use it.

:class:`ChannelPump` holds the C ``Pump`` (pump.c) of one channel: made when the channel's
ROS publisher exists, with one program per spelling of the channel's Gazebo type, and kept for
the publisher's life (its publication sequence numbers are the loop guard's, whichever path
published). The ZeroMQ reader attaches it to the process's one loop (``loop.py``) instead of
reading its socket on a thread of its own (``transport/zmq/reader.py``); what the C loop hands
back is done here in Python: the payloads no program took go through the channel's Python path
(``refused``), which converts them or says why not, with the Python path's own error reasons,
on the process's one fallback thread (``fallback.py``) behind a drop-oldest queue of the
channel's own (its count and bytes), so that a payload that is slow to refuse (a Pose_V of 4 M
empty poses: a second of parsing) holds up no native channel's loop, and a flood of them
holds up another channel's fallback by one payload a turn, not by its whole queue; the frames
of a sender not yet known go to the reader, on the loop's thread.

libzmq and rcl are not linked: their functions are taken from the libraries pyzmq and rclpy
already loaded (docs/native.md §5).
"""

from __future__ import annotations

import ctypes
import functools
import logging
import threading
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import Any

import zmq  # noqa: F401 - loads pyzmq's libzmq, which libzmq_path finds

from ros_gz_bridge_py.converters._limits import amplification_error
from ros_gz_bridge_py.native import extension
from ros_gz_bridge_py.native.fallback import FallbackLane, fallback_worker
from ros_gz_bridge_py.native.loop import shared_loop
from ros_gz_bridge_py.transport import MessageInfo
from ros_gz_bridge_py.transport.api import NativeHost

_LOG = logging.getLogger("ros_gz_bridge_py.native")
_ZMQ_FUNCTIONS = (
    "zmq_msg_init",
    "zmq_msg_recv",
    "zmq_msg_close",
    "zmq_msg_data",
    "zmq_msg_size",
    "zmq_msg_more",
    "zmq_getsockopt",
)
#: Handed back by the C pump: frames it has no route for, a payload no program took, or the
#: figures of a payload refused as too large (no payload: Python would parse it item by item).
_UNROUTED, _REFUSED, _TOO_LARGE = 0, 1, 2


def loaded_libraries() -> list[str]:
    """The paths of the shared libraries this process has loaded (Linux), in load order."""
    try:
        maps = Path("/proc/self/maps").read_text()
    except OSError:
        return []
    paths = [line.rpartition(" ")[2] for line in maps.splitlines()]
    return list(dict.fromkeys(path for path in paths if ".so" in path))


def libzmq_path() -> str | None:
    """The libzmq pyzmq loaded (its wheel bundles one)."""
    return next((path for path in loaded_libraries() if "/libzmq" in path), None)


@functools.cache
def foreign_functions() -> tuple[int, ...] | None:
    """The addresses of the libzmq and rcl functions the pump calls, or None (then no channel
    takes the native path; :func:`why_no_functions` says why)."""
    return _resolve()[0]


def why_no_functions() -> str:
    return _resolve()[1]


@functools.cache
def _resolve() -> tuple[tuple[int, ...] | None, str]:
    path = libzmq_path()  # importing zmq loaded it, with pyzmq's backend
    if path is None:
        return None, "pyzmq's libzmq is not among the loaded libraries"
    try:
        libzmq = ctypes.CDLL(path)
        rcl = ctypes.CDLL("librcl.so")
        rcutils = ctypes.CDLL("librcutils.so")
        functions = [getattr(libzmq, name) for name in _ZMQ_FUNCTIONS]
        functions += [rcl.rcl_publish_serialized_message, rcutils.rcutils_reset_error]
    except (OSError, AttributeError) as err:
        return None, f"libzmq or rcl cannot be used from C ({err})"
    addresses = tuple(ctypes.cast(function, ctypes.c_void_p).value or 0 for function in functions)
    return (addresses, "") if all(addresses) else (None, "a function has no address")


class ChannelPump:
    """One channel's C pump (see the module docstring).

    ``programs``: the compiled program of each wire spelling the channel takes.
    ``refused(payload, info)``: the channel's Python path for one admitted payload.
    ``failed(error)``: counts a payload the C pump refused itself (on the loop's thread).
    """

    def __init__(
        self,
        *,
        topic: str,
        publisher: Any,
        programs: Mapping[str, Any],
        capacity: int,
        max_bytes: int,
        max_rate: float,
        refused: Callable[[bytes, MessageInfo], None],
        failed: Callable[[Exception], None],
        counted: Callable[[int, int, int], None],
        partition: str,
        name: str,
    ) -> None:
        native = extension()
        functions = foreign_functions()
        if native is None or functions is None:
            msg = "no native extension or foreign functions"
            raise RuntimeError(msg)
        self._handle = publisher.handle
        self._pump = native.Pump(
            topic.encode(),
            functions,
            publisher.handle.pointer,
            {name.encode(): program for name, program in programs.items()},
            capacity,
            max_rate,
            max_bytes,
        )
        self._loop = shared_loop()
        self._host: NativeHost | None = None
        self._refused = refused
        self._failed = failed
        self._capacity = capacity
        self._max_bytes = max_bytes
        #: The refused payloads on their way to ``refused`` (made at the first).
        self._fallback: FallbackLane | None = None
        self._closed = False
        self._closing = threading.Lock()  # a lane is not made as the channel closes
        self._counted = counted
        self._partition = partition
        self._name = name
        self._infos: dict[tuple[bytes, bytes], MessageInfo] = {}
        self._seen = (0, 0, 0, 0)

    @property
    def pump(self) -> Any:
        """The C Pump."""
        return self._pump

    # --- the reader -----------------------------------------------------------------------

    def forget(self) -> None:
        """No route is known yet (a closed subscription's queue is dropped); the loop calls it
        when the pump is attached."""
        self._pump.forget()

    def learn(self, sender: bytes, msg_type: bytes, *, take: bool) -> None:
        """Messages of (``sender``, ``msg_type``) go natively from now on (``take``; where a
        program takes the type), or are skipped (another spelling of a type taken)."""
        self._pump.learn(sender, msg_type, take)

    def attach(self, sock: int, monitor: int, host: NativeHost) -> None:
        """Read ``sock`` (with its connection ``monitor``) on the process's loop; ``host`` does
        the reader's share on the loop's thread."""
        self._host = host
        self._loop.attach(self, sock, monitor, self._handle)

    def detach(self) -> None:
        """Returns once the loop no longer reads the socket."""
        self._loop.detach(self)

    def wake(self) -> None:
        """The host wants a turn soon (any thread)."""
        self._loop.ask(self)

    def watch(self, size: int | None) -> None:
        """Payloads larger than ``size`` are told to the host (None: none); on the loop's
        thread, or before the pump is attached."""
        self._pump.watch(-1 if size is None else size)

    # --- the loop's thread ----------------------------------------------------------------

    def loop_turn(self, events: int) -> float | None:
        """What the C loop left to Python: refused payloads converted here, unrouted frames
        judged by the host, the counts; then the host's own turn."""
        loop = self._loop
        handed = self._pump.take_handed() if events & loop.handed_event else ()
        grown = self._pump.take_grown() if events & loop.handed_event else 0
        received, rate_limited, published, _dropped = self.take_counts()
        if received:
            self._counted(received, rate_limited, published)
        unrouted = []
        for item in handed:
            if item[0] == _UNROUTED:
                unrouted.append(item[1])
            elif item[0] == _TOO_LARGE:
                _kind, _sender, _type, items, least, size = item
                self._failed(amplification_error(items, "items", size, items * least))
            else:
                _kind, sender, msg_type, payload, _status = item
                self._fall_back(payload, self._info(sender, msg_type))
        if self._host is None:
            return None
        return self._host.native_turn(
            unrouted,
            monitor=bool(events & loop.monitor_event),
            broken=bool(events & loop.broken_event),
            grown=grown,
        )

    def _fall_back(self, payload: bytes, info: MessageInfo) -> None:
        """``payload`` to the channel's Python path, on the fallback thread."""
        lane = self._fallback
        if lane is None:
            with self._closing:
                if self._closed:
                    return
                worker = fallback_worker()
                lane = self._fallback = worker.lane(self._refused, self._capacity, self._max_bytes)
        lane.put(payload, info)

    @property
    def bytes_read(self) -> int:
        """Payload bytes read from the socket so far (``loop.py`` trims after a burst)."""
        read: int = self._pump.traffic()[0]
        return read

    def close(self) -> None:
        """No more payloads to the Python path (after the one being converted, if it is this
        channel's). Idempotent."""
        with self._closing:
            self._closed = True
            lane = self._fallback
        if lane is not None:
            lane.close()

    def _info(self, sender: bytes, msg_type: bytes) -> MessageInfo:
        info = self._infos.get((sender, msg_type))
        if info is None:
            info = MessageInfo(
                self._name, msg_type.decode(), self._partition, sender.decode(),
                intra_process=False,
            )  # fmt: skip
            self._infos[(sender, msg_type)] = info
        return info

    def take_counts(self) -> tuple[int, int, int, int]:
        """(received, rate_limited, published, dropped) since the last call."""
        received, rate_limited, published, dropped, _skipped, lost = self._pump.counts()
        now = (received, rate_limited, published, dropped + lost)
        before, self._seen = self._seen, now
        return (now[0] - before[0], now[1] - before[1], now[2] - before[2], now[3] - before[3])

    @property
    def received(self) -> int:
        """Payloads taken from the socket so far."""
        return int(self._pump.counts()[0])

    @property
    def dropped_sender(self) -> str:
        """The sender of the last payload dropped ("" before any)."""
        sender: bytes = self._pump.traffic()[1]
        return sender.decode(errors="replace")

    @property
    def dropped(self) -> int:
        """Payloads dropped so far: the oldest, before any work on them (over the queue's count
        or bytes, natively or on the way to the Python path), and those that could not be
        handed to Python (no memory for a copy)."""
        counts = self._pump.counts()
        fallback = self._fallback.dropped if self._fallback is not None else 0
        return int(counts[3] + counts[5]) + fallback

    # --- the loop guard -------------------------------------------------------------------

    def wrap(self, publish: Callable[[Any], None]) -> Callable[[Any], None]:
        """``publish`` (the channel's Python path on the same publisher) numbered in the same
        sequence as the pump's own publications."""
        pump = self._pump

        def publish_and_record(msg: Any) -> None:
            sequence = pump.begin_publication()
            try:
                publish(msg)
            except BaseException:
                pump.end_publication(sequence, False)
                raise
            pump.end_publication(sequence, True)

        return publish_and_record

    def is_own(self, sequence: int, stamp: int) -> bool:
        return bool(self._pump.is_own(sequence, stamp))

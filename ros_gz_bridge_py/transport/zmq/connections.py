"""The publisher addresses one SUB socket is connected to, and what libzmq tells about them.

Three things libzmq does on its own that a SUB socket's owner must follow (docs/protocol-zmq-data.md
§2.8.7):

* ``ZMQ_MAXMSGSIZE``: a frame larger than the limit is refused while its size is read, before
  anything is buffered, by dropping the connection, and libzmq 4.3 does not reconnect after
  that. The socket monitor shows it as a DISCONNECTED event of a connection whose handshake
  had succeeded, with no CONNECT_RETRIED after it (a publisher that goes away is retried). We
  count such a drop as one refused message and reconnect ourselves, sooner after a first
  refusal and up to :data:`MAX_BACKOFF` later when they repeat.
* Connections that end before their handshake (an address that accepts and closes, wrong
  credentials, something that is not ZeroMQ): libzmq retries those every 100 ms for ever (a
  successful TCP connect resets its back-off). From the second such failure in a row we
  disconnect the address and retry it ourselves with the back-off. Wrong credentials
  (HANDSHAKE_FAILED_AUTH) are also counted and said once per address.
* Disconnecting: ``zmq_disconnect`` while a message's first frame was already taken from the
  connection's pipe (``zmq_poll`` prefetches it) makes the next read abort the process
  (``Assertion failed: !_more (src/fq.cpp)``, libzmq issue #2163). :meth:`SubConnections.
  disconnect` therefore first reads whole messages until the socket is empty (``drain``), on the
  socket's own thread, so no poll comes between the last read and the disconnect.
* ``zmq_disconnect`` also discards what the connection delivers after it. A publisher that
  sends its last message and exits announces its leaving (UNADVERTISE) as it exits, and that
  datagram can come before the message is on the wire: ``ign topic -p`` sent its one message
  0.4 ms after its UNADVERTISE (``strace``), and disconnecting at once lost two one-shots of
  three where not disconnecting lost one of four, as a C++ subscriber does. An address whose
  publishers are gone is therefore disconnected :data:`LEAVE_AFTER` later
  (:meth:`SubConnections.leave`), unless a publisher comes back there first.
"""

from __future__ import annotations

import contextlib
import logging
import struct
import time
from collections.abc import Callable
from typing import Any

import zmq

_LOG = logging.getLogger("ros_gz_bridge_py.transport")

#: A monitor message's first frame: the event (16 bits) and its value (32 bits), native order.
_MONITOR_EVENT = struct.Struct("=HI")


def monitor_event(frames: list[bytes]) -> tuple[int, str] | None:
    """(event, endpoint) of a message of libzmq's socket monitor; None if it is not one.

    pyzmq's ``zmq.utils.monitor`` does the same, but importing it imports asyncio, a tenth of
    the Gazebo node's start-up (docs/environment.md §3).
    """
    if len(frames) != 2 or len(frames[0]) != _MONITOR_EVENT.size:
        return None
    kind, _value = _MONITOR_EVENT.unpack(frames[0])
    return kind, frames[1].decode(errors="replace")


#: The monitor events we follow.
EVENTS = (
    zmq.EVENT_CONNECTED
    | zmq.EVENT_CONNECT_DELAYED
    | zmq.EVENT_CONNECT_RETRIED
    | zmq.EVENT_DISCONNECTED
    | zmq.EVENT_HANDSHAKE_SUCCEEDED
    | zmq.EVENT_HANDSHAKE_FAILED_AUTH
)
#: A DISCONNECTED event not followed by a retry within this long was libzmq giving up (s).
CONFIRM_AFTER = 0.2
#: First delay before we reconnect after a refusal or failed handshake (s) ...
FIRST_BACKOFF = 0.1
#: ... doubled at each repetition, up to this (s); also libzmq's own ZMQ_RECONNECT_IVL_MAX.
MAX_BACKOFF = 5.0
#: A refusal this long after the previous one starts the back-off anew (s).
BACKOFF_RESET = 30.0
#: Connections ending before their handshake, in a row, after which we take over retrying.
FAILURES_BEFORE_BACKOFF = 2
#: Monitor events read per turn.
READ_BATCH = 256
#: How long an address stays connected after its last publisher is gone (s; see above).
LEAVE_AFTER = 0.5


class SubConnections:
    """One SUB socket's publisher connections (used on the socket's own thread only).

    ``drain`` reads whole messages until the socket is empty (or a batch is done);
    ``on_refused(address)`` is called for each message refused for its size.
    """

    def __init__(
        self,
        sock: Any,
        *,
        drain: Callable[[], None],
        on_refused: Callable[[str], None],
        count: Callable[..., None],
        what: str,
    ) -> None:
        self._sock = sock
        self._drain = drain
        self._on_refused = on_refused
        self._count = count
        self._what = what
        self.monitor: Any = sock.get_monitor_socket(EVENTS)
        self.connected: set[str] = set()
        self._handshaken: set[str] = set()
        self._auth_failed: set[str] = set()
        self._told_auth: set[str] = set()
        # address -> connections in a row that ended before their handshake
        self._failures: dict[str, int] = {}
        # address -> when libzmq dropped it (waiting to see whether it retries)
        self._dropped: dict[str, float] = {}
        # address -> when to reconnect; address -> (delay, time of the last refusal)
        self._due: dict[str, float] = {}
        self._backoff: dict[str, tuple[float, float]] = {}
        # address -> when to disconnect it (its publishers are gone)
        self._leaving: dict[str, float] = {}

    def connect(self, address: str) -> bool:
        """Connect once per address; False (counted, logged) if libzmq refuses it. An address
        that is :meth:`leave`-ing stays."""
        if address in self.connected:
            self._leaving.pop(address, None)
            return True
        try:
            self._sock.connect(address)
        except zmq.ZMQError as error:
            self._count("addresses_refused")
            _LOG.debug("cannot connect %s to publisher %r: %s", self._what, address, error)
            return False
        self.connected.add(address)
        return True

    def leave(self, address: str) -> None:
        """Disconnect ``address`` :data:`LEAVE_AFTER` from now: its publishers are gone, and
        what they sent last may still be on its way (see the module docstring)."""
        if address in self.connected and address not in self._leaving:
            self._leaving[address] = time.monotonic() + LEAVE_AFTER

    def disconnect(self, address: str) -> None:
        """Stop connecting to ``address`` now (safely, see the module docstring)."""
        if address not in self.connected:
            return
        self._forget(address)
        self.connected.discard(address)
        self._drain()
        with contextlib.suppress(zmq.ZMQError):  # already gone on libzmq's side
            self._sock.disconnect(address)
        self._count("publishers_disconnected")

    def next_deadline(self) -> float | None:
        """When :meth:`turn` next has something to do (None: only on a monitor event)."""
        if not self._dropped and not self._due and not self._leaving:
            return None
        times = [t + CONFIRM_AFTER for t in self._dropped.values()]
        return min([*times, *self._due.values(), *self._leaving.values()])

    def is_due(self, now: float) -> bool:
        """True when :meth:`turn` has something to do at ``now`` besides monitor events."""
        deadline = self.next_deadline()
        return deadline is not None and deadline <= now

    def turn(self, now: float | None = None) -> None:
        """Read the monitor, disconnect what is leaving, confirm drops libzmq does not retry,
        reconnect what is due."""
        now = time.monotonic() if now is None else now
        self._read_events(now)
        for address, when in list(self._leaving.items()):
            if now >= when:
                self.disconnect(address)
        for address, when in list(self._dropped.items()):
            if now - when >= CONFIRM_AFTER:
                del self._dropped[address]
                if address not in self._leaving:  # else it went with its publishers
                    self._given_up(address, now)
        for address, when in list(self._due.items()):
            if now >= when:
                del self._due[address]
                self._reconnect(address)

    def close(self) -> None:
        with contextlib.suppress(zmq.ZMQError):
            self._sock.disable_monitor()
        self.monitor.close(linger=0)

    # --- internals --------------------------------------------------------------------------

    def _read_events(self, now: float) -> None:
        if not self.monitor.get(zmq.EVENTS) & zmq.POLLIN:
            return  # mostly: an idle turn would otherwise raise and catch zmq.Again
        for _ in range(READ_BATCH):
            try:
                frames = self.monitor.recv_multipart(zmq.NOBLOCK)
            except zmq.Again:
                return
            event = monitor_event(frames)
            if event is not None and event[1] in self.connected:
                self._on_event(*event, now)

    def _on_event(self, kind: int, address: str, now: float) -> None:
        if kind == zmq.EVENT_HANDSHAKE_SUCCEEDED:
            self._handshaken.add(address)
            self._auth_failed.discard(address)
            self._failures.pop(address, None)
        elif kind == zmq.EVENT_HANDSHAKE_FAILED_AUTH:
            self._auth_failed.add(address)
            self._count("auth_failures")
            if address not in self._told_auth:
                self._told_auth.add(address)
                _LOG.warning(
                    "%s: the publisher at %s refused our credentials: check that "
                    "GZ_TRANSPORT_USERNAME and GZ_TRANSPORT_PASSWORD (IGN_ for Fortress) are the "
                    "same in both processes",
                    self._what,
                    address,
                )
        elif kind == zmq.EVENT_DISCONNECTED and address in self._handshaken:
            self._dropped[address] = now  # a refused message, if libzmq does not retry
        elif kind == zmq.EVENT_DISCONNECTED:
            failures = self._failures[address] = self._failures.get(address, 0) + 1
            if failures >= FAILURES_BEFORE_BACKOFF and address not in self._due:
                self._drain()
                with contextlib.suppress(zmq.ZMQError):
                    self._sock.disconnect(address)
                self._schedule(address, now)
        else:  # CONNECTED, CONNECT_DELAYED, CONNECT_RETRIED: libzmq is on it
            self._dropped.pop(address, None)

    def _given_up(self, address: str, now: float) -> None:
        """libzmq dropped ``address`` for good: a refused message, or a failed handshake."""
        if address in self._handshaken and address not in self._auth_failed:
            self._on_refused(address)
        self._handshaken.discard(address)
        self._schedule(address, now)

    def _schedule(self, address: str, now: float) -> None:
        """Reconnect ``address`` after the back-off: FIRST_BACKOFF, doubled each time within
        BACKOFF_RESET of the previous, up to MAX_BACKOFF."""
        delay, last = self._backoff.get(address, (0.0, 0.0))
        delay = FIRST_BACKOFF if now - last > BACKOFF_RESET else min(2 * delay, MAX_BACKOFF)
        self._backoff[address] = (max(delay, FIRST_BACKOFF), now)
        self._due[address] = now + delay

    def _reconnect(self, address: str) -> None:
        self._drain()
        with contextlib.suppress(zmq.ZMQError):
            self._sock.disconnect(address)
        try:
            self._sock.connect(address)
        except zmq.ZMQError as error:
            self.connected.discard(address)
            _LOG.debug("cannot reconnect %s to %r: %s", self._what, address, error)

    def _forget(self, address: str) -> None:
        for table in (self._dropped, self._due, self._backoff, self._failures, self._leaving):
            table.pop(address, None)
        for names in (self._handshaken, self._auth_failed, self._told_auth):
            names.discard(address)

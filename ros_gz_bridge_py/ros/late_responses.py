"""Service responses for a client the middleware has not finished discovering.

A ROS client may call as soon as its request writer is matched with the service; the service's
response writer may not have matched the client's response reader yet (discovery of the two
endpoints is not atomic, and on a loaded machine it can lag by seconds). rmw_fastrtps then waits
for the match up to the writer's ``max_blocking_time`` (100 ms) and gives up: rcl returns
``RCL_RET_TIMEOUT``, rclpy turns it into ``RuntimeWarning: failed to send response (timeout)``
and the response is gone, so the client waits for ever (rclcpp logs and drops it the same way,
so the C++ bridge loses it too). Here such a response is held and sent again every
:data:`RETRY_PERIOD` until it goes out (the client was discovered, or is gone), or until
:data:`PATIENCE` has passed; then it is given up, told and counted by its owner.

rclpy's warning is turned into an exception only for the call made from this module (a warnings
filter scoped to this module's name, put first before each call), so nobody else's warnings
change. The warning is raised
from a pybind11 function that does not report it, so Python sees a ``SystemError`` whose cause
is the warning; both forms are recognised.
"""

from __future__ import annotations

import re
import threading
import time
import warnings
from collections import deque
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, Protocol

from rclpy.callback_groups import MutuallyExclusiveCallbackGroup
from rclpy.exceptions import InvalidHandle

#: What rclpy's warning starts with when rmw could not deliver a response in time.
TIMEOUT_WARNING = "failed to send response (timeout)"
#: Seconds between two attempts at the held responses (each attempt itself waits up to the
#: response writer's max_blocking_time for the match).
RETRY_PERIOD = 0.1
#: Seconds a response waits for its client to be discovered before it is given up.
PATIENCE = 10.0
#: Responses held at once; one more gives up the oldest (each attempt at a client that never
#: matches takes max_blocking_time of the retrying thread).
MAX_HELD = 32

_MESSAGE = re.escape(TIMEOUT_WARNING)
_MODULE = re.escape(__name__) + r"\Z"


class ResponseOwner(Protocol):
    """Who hears what became of a held response (the service bridge, which counts it)."""

    def answered_late(self, waited: float) -> None: ...

    def not_answered(self, waited: float, why: str) -> None: ...


def _is_timeout(error: BaseException | None) -> bool:
    return isinstance(error, RuntimeWarning) and str(error).startswith(TIMEOUT_WARNING)


def _timeout_raises_here() -> None:
    """Put the filter that makes rclpy's timeout warning, raised from this module, an error
    first among the filters (again if anyone reset or overrode them: pytest does, per test)."""
    first = warnings.filters[0] if warnings.filters else None
    if not (
        first is not None
        and first[0] == "error"
        and getattr(first[1], "pattern", None) == _MESSAGE
        and getattr(first[3], "pattern", None) == _MODULE
    ):
        warnings.filterwarnings("error", _MESSAGE, RuntimeWarning, _MODULE)


def send_once(service: Any, response: Any, header: Any) -> bool:
    """Send ``response`` to the client of ``header``: False when rmw timed out waiting for the
    client's response reader (the response did not go out), True otherwise (it went out, or the
    client is gone and rmw dropped it)."""
    request_id = getattr(header, "request_id", header)
    _timeout_raises_here()
    try:
        with service.handle:
            service.handle.service_send_response(response, request_id)
    except RuntimeWarning as error:
        if _is_timeout(error):
            return False
        raise
    except SystemError as error:
        if _is_timeout(error.__cause__):
            return False
        raise
    return True


@dataclass
class _Held:
    service: Any
    response: Any
    header: Any
    owner: ResponseOwner
    since: float


class LateResponses:
    """The held responses of one node's services and the timer that sends them again."""

    def __init__(
        self,
        node: Any,
        *,
        send: Callable[[Any, Any, Any], bool] = send_once,
        clock: Callable[[], float] = time.monotonic,
        patience: float = PATIENCE,
        limit: int = MAX_HELD,
    ) -> None:
        self._node = node
        self._send = send
        self._clock = clock
        self.patience = patience
        self.limit = limit
        self._held: deque[_Held] = deque()
        self._lock = threading.Lock()
        self._group = MutuallyExclusiveCallbackGroup()
        self._timer: Any = None

    def serve(self, service: Any, owner: ResponseOwner) -> None:
        """Route the responses rclpy's executor sends for ``service`` through here."""

        def send_response(response: Any, header: Any) -> None:
            if not self._send(service, response, header):
                self._hold(_Held(service, response, header, owner, self._clock()))

        service.send_response = send_response

    @property
    def held(self) -> int:
        with self._lock:
            return len(self._held)

    def _hold(self, held: _Held) -> None:
        with self._lock:
            self._held.append(held)
            oldest = self._held.popleft() if len(self._held) > self.limit else None
            if self._timer is None:
                self._timer = self._node.create_timer(
                    RETRY_PERIOD, self.retry, callback_group=self._group
                )
            elif self._timer.is_canceled():
                self._timer.reset()
        if oldest is not None:
            oldest.owner.not_answered(
                self._clock() - oldest.since,
                f"{self.limit} responses already waited for their clients to be discovered",
            )

    def retry(self) -> None:
        """Send each held response once more (the timer's callback)."""
        with self._lock:
            batch = list(self._held)
            self._held.clear()
        kept = []
        for held in batch:
            try:
                sent = self._send(held.service, held.response, held.header)
            except InvalidHandle:
                continue  # the service is destroyed: the bridge is closing
            waited = self._clock() - held.since
            if sent:
                held.owner.answered_late(waited)
            elif waited >= self.patience:
                held.owner.not_answered(
                    waited,
                    "its client was never discovered (a client gone unseen, or one whose "
                    "response QoS the service cannot match, such as transient_local durability)",
                )
            else:
                kept.append(held)
        with self._lock:
            self._held.extendleft(reversed(kept))
            if not self._held and self._timer is not None:
                self._timer.cancel()

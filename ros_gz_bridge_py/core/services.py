"""Service bridges: a ROS service whose requests are forwarded to a Gazebo service.

Service bridges live on the bridge's side node (``ros/side_node.py``), spun by a multi-threaded
executor in its own thread. Each call is a coroutine: it converts the request, sends it to
Gazebo asynchronously, and awaits the reply or the timeout without holding a thread, so any
number of calls can wait at once; it returns exactly one response: the converted reply, or
``success=False`` when Gazebo reports failure, does not answer in time, the request cannot be
converted, or :data:`MAX_WAITING` calls, or ``max_queued_bytes`` of them, already wait
(answered at once, never dropped). The bytes are the requests sent to Gazebo and the replies
that came back but are not converted yet (:class:`HeldBytes`); a reply that would take them
past the budget is not kept, and its call is answered ``success=False``. The server keeps
:data:`REQUEST_DEPTH` requests, so a burst of clients is not overwritten before it is taken.
A response for a client the middleware has not finished discovering is sent again until it goes
out (``ros/late_responses.py``); one given up is counted as dropped and told.
The C++ bridge can answer twice, never answers when Gazebo is absent, loses the response of a
client discovered late, and holds a thread per waiting call. Keeping calls off the main
executor means a slow or absent Gazebo service never delays topic traffic (the EventsExecutor
also cannot run coroutine callbacks).
"""

from __future__ import annotations

import collections
import threading
import time
from collections.abc import Callable
from typing import Any

from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
from rclpy.task import Future

from ros_gz_bridge_py.config import ServiceBridgeSpec
from ros_gz_bridge_py.config.names import renamed
from ros_gz_bridge_py.converters.registry import ServicePair
from ros_gz_bridge_py.errors import ConfigError
from ros_gz_bridge_py.msgs import message_class
from ros_gz_bridge_py.msgs.names import same_message
from ros_gz_bridge_py.ros.quick_log import quick_logger
from ros_gz_bridge_py.ros.side_node import SideNode
from ros_gz_bridge_py.transport import GzNode
from ros_gz_bridge_py.transport.delivery import DROP_WARN_PERIOD, MAX_QUEUED_BYTES
from ros_gz_bridge_py.transport.throttle import Throttle

DEFAULT_TIMEOUT = 5.0
#: Requests the ROS service server keeps before they are taken (rclpy's default is 10, and a
#: burst of clients beyond it was overwritten without an answer).
REQUEST_DEPTH = 1000
#: Calls that may wait for Gazebo at once; one more is answered ``success=false`` at once.
MAX_WAITING = 1000
#: Seconds closing waits for the waiting calls' answers (``success=false``) to go out.
CLOSE_PATIENCE = 1.0
#: What a failed call's reason is counted as (``ServiceBridge.failures_by_reason``).
NOT_CONVERTED = "not converted"


class HeldBytes:
    """The bytes a service bridge's waiting calls hold, within a budget (any thread): a
    request is admitted when it fits, or when no call waits (one call is always let through,
    as a queue always keeps one message); a reply is kept when it fits, or when its call is
    the only one waiting."""

    def __init__(self, budget: int) -> None:
        self.budget = budget
        self.held = 0
        self.calls = 0
        self._lock = threading.Lock()

    def admit(self, size: int) -> bool:
        """Hold ``size`` bytes of a new call's request; False (nothing held) when over."""
        with self._lock:
            if self.calls and self.held + size > self.budget:
                return False
            self.calls += 1
            self.held += size
            return True

    def keep(self, size: int) -> bool:
        """Hold ``size`` bytes of a waiting call's reply; False (nothing held) when over."""
        with self._lock:
            if self.calls > 1 and self.held + size > self.budget:
                return False
            self.held += size
            return True

    def release(self, size: int) -> None:
        """A call is answered: its ``size`` bytes (request and kept reply) go."""
        with self._lock:
            self.calls -= 1
            self.held -= size


def resolve_gz_types(spec: ServiceBridgeSpec, pair: ServicePair) -> tuple[str, str]:
    """The Gazebo request/reply type strings to use on the wire for ``spec``.

    Omitted types take the pair's defaults. Given types must name the pair's types, in either
    spelling (``gz.msgs.X`` or, for Fortress, ``ignition.msgs.X``); the spelling is kept because
    Gazebo matches service types as exact strings.

    Raises:
        ConfigError: a given type is not the one this ROS service type converts to.
    """
    chosen = []
    for given, expected, what in (
        (spec.gz_req_type, pair.gz_req_type, "request"),
        (spec.gz_rep_type, pair.gz_rep_type, "reply"),
    ):
        if not given:
            chosen.append(expected)
        elif same_message(given, expected):
            chosen.append(given)
        else:
            msg = (
                f"service [{spec.service}] of type [{spec.ros_type}] needs Gazebo {what} type "
                f"[{expected}], not [{given}]; omit the Gazebo types to use the defaults"
            )
            raise ConfigError(msg, spec.source or None)
    return chosen[0], chosen[1]


class ServiceBridge:
    """One ROS service forwarded to one Gazebo service."""

    def __init__(
        self,
        host: SideNode,
        gz_node: GzNode,
        spec: ServiceBridgeSpec,
        pair: ServicePair,
        timeout: float = DEFAULT_TIMEOUT,
        *,
        max_queued_bytes: int = MAX_QUEUED_BYTES,
        ros_types_for: Callable[[str, str], list[str]] = lambda _request, _reply: [],
    ) -> None:
        """``ros_types_for(request, reply)``: the ROS service types converting to those Gazebo
        types (a provider of other types is told which one to bridge it with)."""
        self.spec = spec
        self._ros_types_for = ros_types_for
        self.pair = pair
        self.timeout = timeout
        self.gz_req_type, self.gz_rep_type = resolve_gz_types(spec, pair)
        self._reply_class = message_class(self.gz_rep_type)
        self._host = host
        self._ros_node = host.node
        self._gz_node = gz_node
        self._logger = quick_logger(host.owner.get_logger())  # the bridge's name, not the side's
        self.calls = 0
        self.failures = 0
        #: Failed calls by what went wrong, and the last one's reason in full.
        self.failures_by_reason: collections.Counter[str] = collections.Counter()
        self.last_failure = ""
        self.waiting = 0
        #: The replies the waiting calls await; closing answers them (``close``).
        self._awaited: set[Future] = set()
        self._settling = threading.Lock()
        self._closing = False
        #: The bytes the waiting calls hold, within ``max_queued_bytes``.
        self.held = HeldBytes(max_queued_bytes)
        #: Calls answered at once because the waiting ones held the budget.
        self.refused_over_bytes = 0
        self._warnings = Throttle(DROP_WARN_PERIOD)
        #: Responses sent again once their client was discovered, and responses given up.
        self.late_answers = 0
        self.unanswered = 0
        self._late_notes = Throttle(DROP_WARN_PERIOD)
        #: The name the bridge's node resolves ``spec.service`` to (its remap rules, which the
        #: side node that serves it does not take: ``ros/side_node.py``).
        self.service_name: str = host.owner.resolve_service_name(spec.service)
        self._service = host.node.create_service(
            pair.ros_class,
            self.service_name,
            self._on_request,
            qos_profile=QoSProfile(
                depth=REQUEST_DEPTH,
                reliability=ReliabilityPolicy.RELIABLE,
                durability=DurabilityPolicy.VOLATILE,
            ),
            callback_group=host.reentrant,
        )
        host.late_responses.serve(self._service, self)

    def describe(self) -> str:
        """``ROS->GZ service [<name> (<ROS type> -> <request>/<reply>)]`` with the resolved
        name and the Gazebo types in use: what the service's own log lines start with."""
        return (
            f"ROS->GZ service [{self.service_name} ({self.spec.ros_type} -> "
            f"{self.gz_req_type}/{self.gz_rep_type})]"
        )

    def creation_lines(self) -> list[str]:
        """What the bridge logs on creating the service: the C++ bridge's line word for word
        (the name and types as configured, a left-out type empty; docs/behaviour.md §5),
        then, when the ROS name resolved to another or a Gazebo type was left out, a line of
        ours saying what is used."""
        spec = self.spec
        given = f"{spec.gz_req_type or ''}/{spec.gz_rep_type or ''}"
        lines = [f"Creating ROS->GZ service bridge [{spec.service} ({spec.ros_type} -> {given})]"]
        notes = []
        if renamed(spec.service, self.service_name):
            notes.append(f"the ROS name {spec.service} resolves to {self.service_name}")
        if not (spec.gz_req_type and spec.gz_rep_type):
            notes.append("the Gazebo types left out are the service type's")
        if notes:
            lines.append(f"{self.describe()}: {'; '.join(notes)}")
        return lines

    async def _on_request(self, request: Any, _response: Any) -> Any:
        """One call, answered once: never raises (an exception would leave it unanswered)."""
        self.calls += 1
        if self._closing:
            return self._fail("the bridge is shutting down", "shutting down")
        if self.waiting >= MAX_WAITING:
            why = f"{self.waiting} calls already wait for Gazebo; try again later"
            return self._fail(why, "too many waiting")
        try:
            payload = self.pair.request_to_gz(request).SerializeToString()
        except Exception as err:
            return self._fail(f"request not converted: {err}", NOT_CONVERTED)
        if not self.held.admit(len(payload)):
            return self._refuse(len(payload))
        self.waiting += 1
        held = [len(payload)]
        try:
            return await self._forward(payload, held)
        except Exception as err:
            return self._fail(f"request failed: {err}", "request failed")
        finally:
            self.waiting -= 1
            self.held.release(sum(held))

    def _refuse(self, size: int) -> Any:
        """A call over the byte budget: answered at once, counted, told once per period."""
        self._count_failure(f"a request of {size} bytes over max_queued_bytes", "over budget")
        self.refused_over_bytes += 1
        if self._warnings.ready("refused"):
            self._logger.warning(
                f"{self.describe()}: a request of {size} bytes refused (success=false): "
                f"{self.held.calls} calls holding {self.held.held} bytes already wait for "
                f"Gazebo, at most {self.held.budget} bytes (parameter max_queued_bytes); "
                f"{self.refused_over_bytes} refused so far"
            )
        return self.pair.failure_to_ros()

    async def _forward(self, payload: bytes, held: list[int]) -> Any:
        """Send ``payload`` and await the reply; ``held`` gets the bytes of a kept reply."""
        future = self._host.future()
        dropped: list[int] = []

        def on_reply(ok: bool | None, reply: bytes) -> None:
            if ok and not self.held.keep(len(reply)):
                dropped.append(len(reply))  # not kept: only its size waits for the executor
                ok, reply = None, b""
            elif ok is not None:
                held.append(len(reply))
            self._settle(future, (ok, reply))

        with self._settling:
            self._awaited.add(future)
        served = not self.provider_problem()[0]  # a provider of our types is known now
        try:
            self._gz_node.request_async(
                self.spec.service, payload, self.gz_req_type, self.gz_rep_type, self.timeout,
                on_reply,
            )  # fmt: skip
            success, reply = await future
        finally:
            with self._settling:
                self._awaited.discard(future)
        if dropped:
            return self._fail(
                f"the reply of {dropped[0]} bytes is not kept: with the {self.held.calls} "
                f"waiting calls' {self.held.held} bytes it is over {self.held.budget} bytes "
                "(parameter max_queued_bytes)",
                "over budget",
            )
        if self._closing and success is None:
            return self._fail("the bridge is shutting down", "shutting down")
        if success is None:
            return self._fail(self._no_reply(served), "no reply")
        if not success:
            return self._fail("Gazebo reported failure", "Gazebo failure")
        try:
            return self.pair.reply_to_ros(self._reply_class.FromString(reply))
        except Exception as err:
            return self._fail(f"reply not converted: {err}", NOT_CONVERTED)

    def _no_reply(self, served: bool) -> str:
        """Why Gazebo did not answer in time, as far as discovery knows; ``served``: a
        provider of the bridge's types was known when the call was made."""
        waited = f"{self.timeout:g} s"
        if served and not self._gz_node.service_info(self.spec.service):
            why = (
                "the Gazebo provider known when the call was made went silent (a simulator "
                "busy or stopped: discovery forgets a process silent for 3 s)"
            )
        else:
            why, _ = self.provider_problem()
        return (
            f"no reply within {waited}: {why}" if why else f"no reply from Gazebo within {waited}"
        )

    def provider_problem(self) -> tuple[str, bool]:
        """What discovery says keeps calls from being answered: ("", False) when a provider
        of the bridge's types is known; (why, True) when the providers take other types (a
        misconfiguration), (why, False) when there is none yet."""
        service = self.spec.service
        providers = self._gz_node.service_info(service)
        if not providers:
            why = (
                f"no Gazebo provider of {service} is known (gz service -l, ign service -l on "
                "Fortress, lists the services there are)"
            )
            return why, False
        offered = {(p.request_type, p.response_type) for p in providers}
        if any(
            same_message(request, self.gz_req_type) and same_message(reply, self.gz_rep_type)
            for request, reply in offered
        ):
            return "", False
        types = ", ".join(sorted(f"{request}/{reply}" for request, reply in offered))
        theirs = sorted({t for pair in offered for t in self._ros_types_for(*pair)})
        named = " or ".join(theirs) or (
            "the ROS type of theirs (bridge_types --print-pairs lists the service pairs)"
        )
        why = (
            f"the Gazebo providers of {service} take {types}, not "
            f"{self.gz_req_type}/{self.gz_rep_type}, the only types {self.spec.ros_type} "
            f"converts to; bridge the service with {named}, or make the provider take these"
        )
        return why, True

    def _settle(self, future: Future, outcome: tuple[bool | None, bytes]) -> None:
        """The call's outcome, once (a reply, its timeout, or closing: whichever is first)."""
        with self._settling:
            if future.done():
                return
            future.set_result(outcome)

    def answered_late(self, waited: float) -> None:
        """A held response went out once its client was discovered (late_responses.py)."""
        self.late_answers += 1
        if self._late_notes.ready():
            self._logger.info(
                f"{self.describe()}: a response went out {waited:.2f} s late, when the "
                f"middleware had discovered its client; {self.late_answers} so far"
            )

    def not_answered(self, waited: float, why: str) -> None:
        """A held response is given up after ``waited`` seconds (late_responses.py); told once
        per period, counted in full."""
        self.unanswered += 1
        if self._warnings.ready("unanswered"):
            self._logger.warning(
                f"{self.describe()}: a response is given up after {waited:.1f} s: {why}; "
                f"{self.unanswered} given up so far"
            )

    def _fail(self, why: str, reason: str) -> Any:
        """A call answered success=false: counted, told once per period."""
        self._count_failure(why, reason)
        if self._warnings.ready("failed"):
            self._logger.warning(f"{self.describe()}: {why}; {self.failures} failed so far")
        return self.pair.failure_to_ros()

    def _count_failure(self, why: str, reason: str) -> None:
        self.failures += 1
        self.failures_by_reason[reason] += 1
        self.last_failure = why

    def close(self) -> None:
        """The waiting calls answered ``success=false`` (their clients are not left without
        an answer), then the service goes."""
        self._closing = True
        with self._settling:
            awaited = [future for future in self._awaited if not future.done()]
        for future in awaited:
            self._settle(future, (None, b""))
        deadline = time.monotonic() + CLOSE_PATIENCE
        while self.waiting and time.monotonic() < deadline:
            time.sleep(0.01)
        if self._service is not None:
            self._ros_node.destroy_service(self._service)
            self._service = None

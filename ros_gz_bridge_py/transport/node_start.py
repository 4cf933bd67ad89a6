"""Start a node while the caller can still be stopped.

A Zenoh client that waits for its router (``connect/timeout_ms``, docs/zenoh.md) blocks in
Zenoh's native code; the executables' SIGINT/SIGTERM handlers run on the main thread only when
it is back in Python, so Ctrl-C did nothing for the whole wait (for ever with ``-1``). The
node is started on a thread of its own instead, and the caller's thread looks at the stop
request every 0.1 s.
"""

from __future__ import annotations

import logging
import threading
from collections.abc import Callable

from ros_gz_bridge_py.errors import TransportError
from ros_gz_bridge_py.transport.node import GzNode

_LOG = logging.getLogger("ros_gz_bridge_py.transport")
#: Seconds a start may take before the log says the bridge waits for it.
SLOW_START = 2.0
STOPPED = "stopped before the Gazebo Transport node had started"


def start_unless_stopped(
    start: Callable[[], GzNode], stop_requested: Callable[[], bool], implementation: str
) -> GzNode:
    """``start()``'s node, unless ``stop_requested()`` says True first (a node that starts
    after that is closed on its own thread).

    Raises:
        TransportError: the start failed (its own error), or :data:`STOPPED`.
    """
    lock = threading.Lock()
    done = threading.Event()
    outcome: list[GzNode | BaseException] = []
    abandoned = False

    def run() -> None:
        try:
            result: GzNode | BaseException = start()
        except BaseException as err:  # raised again on the caller's thread
            result = err
        with lock:
            if not abandoned:
                outcome.append(result)
                done.set()
                return
        if isinstance(result, GzNode):
            result.close()

    threading.Thread(target=run, name="gz-node-start", daemon=True).start()
    waited = 0.0
    while not done.wait(0.1):
        waited += 0.1
        if stop_requested():
            with lock:
                if not done.is_set():
                    abandoned = True
                    raise TransportError(STOPPED)
        if SLOW_START <= waited < SLOW_START + 0.1:
            _LOG.warning(
                "the %s node has not started after %g s (a Zenoh client waits for its router); "
                "still waiting, Ctrl-C stops",
                implementation,
                SLOW_START,
            )
    (result,) = outcome
    if isinstance(result, BaseException):
        raise result
    return result

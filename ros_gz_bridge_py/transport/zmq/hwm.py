"""The high-water mark that keeps a ZeroMQ queue within a byte budget.

libzmq bounds each pipe's queue by a count of messages (SNDHWM, RCVHWM), whatever their
size: 1000 images of 6 MB are 6 GB. A socket whose owner lowers that count as the messages
it carries grow keeps the queue under the bridge's ``max_queued_bytes`` instead. libzmq
applies a changed HWM to the pipes already open (``socket_base_t::update_pipe_options``), so
the count may be lowered while peers are connected, by the thread that owns the socket.
"""

from __future__ import annotations

#: The fewest messages a byte-bounded queue holds, however large they are: one in flight and
#: one waiting, so a peer that keeps up loses nothing to a single large message.
MIN_HWM = 2


def hwm_for_bytes(largest: int, budget: int, configured: int) -> int:
    """The HWM for a queue of messages up to ``largest`` bytes that should hold at most
    ``budget`` bytes, never more than ``configured`` messages (0: no count limit, libzmq's
    meaning) and never fewer than :data:`MIN_HWM` (or ``configured``, when that is less).

    Before any message (``largest`` <= 0) the configured count holds.
    """
    if largest <= 0:
        return configured
    fits = max(MIN_HWM, budget // largest)
    return fits if configured <= 0 else min(configured, fits)

"""The high-water mark that keeps a ZeroMQ queue within a byte budget.

libzmq bounds each pipe's queue by a count of messages (SNDHWM, RCVHWM), whatever their
size: 1000 images of 6 MB are 6 GB. A socket whose mark is the number of its largest messages
that fit in the bridge's ``max_queued_bytes`` keeps each queue under that budget instead.

The mark must be set before the socket is bound or connected, never after (docs/protocol-zmq-data.md
§2.8.8): a pipe takes the socket's mark when it is made; libzmq 4.3.5 applies a changed mark to
the pipes already made, but a lowered one can leave a live pipe stalled for good (the writer's
count of what was read lags by up to the old low-water mark), and changing it while a peer
disconnects sends a command to a pipe already freed (a crash in libzmq's I/O thread).
"""

from __future__ import annotations

#: The fewest messages a byte-bounded queue holds, however large they are: one in flight and
#: one waiting, so a peer that keeps up loses nothing to a single large message.
MIN_HWM = 2
#: The largest mark libzmq takes (a C int).
MAX_HWM = 2**31 - 1


def hwm_for_bytes(largest: int, budget: int, configured: int) -> int:
    """The HWM for a queue of messages up to ``largest`` bytes that should hold at most
    ``budget`` bytes, never more than ``configured`` messages (0: no count limit, libzmq's
    meaning) and never fewer than :data:`MIN_HWM` (or ``configured``, when that is less).

    Before any message (``largest`` <= 0) the configured count holds.
    """
    if largest <= 0:
        return configured
    fits = min(MAX_HWM, max(MIN_HWM, budget // largest))
    return fits if configured <= 0 else min(configured, fits)

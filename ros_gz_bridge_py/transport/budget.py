"""The fairness budget: what one channel gets per turn before the others have theirs.

One thread serves many channels (a native loop, docs/native.md §5) or reads and delivers for
one (a reader's thread, ``zmq/reader.py``); either way a flooded channel must not hold the
thread: each gets at most :data:`TURN_MESSAGES` messages read and as many delivered, and its
deliveries stop after :data:`TURN_SLICE` seconds, then the thread moves on (the others' turns,
or reading its socket again). Defined here once: a native loop's C struct (``struct
rgb_budget``) is filled from these values when the loop is made, and the Python reader reads
them itself.
"""

from __future__ import annotations

#: Messages a channel reads (or takes), and delivers, per turn.
TURN_MESSAGES = 64
#: Longest time (s) a channel's deliveries go on per turn.
TURN_SLICE = 0.001

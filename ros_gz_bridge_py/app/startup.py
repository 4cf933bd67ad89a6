"""The executables' start-up: what waits until the channels exist.

The bridge's node holds its own services back until then (``ros/bridge_node.py``), and so is
Python's cyclic garbage collector: :func:`finish_start_up` releases both.

Loading the modules and creating the channels makes some 100 000 objects, and the collector
ran about 90 times over them before the first channel existed (about 0.01 s of a 0.2 s start,
docs/environment.md §3). The entry points pause it (:func:`pause_collector`, imported before
rclpy); once the channels exist, :func:`resume_collector` collects start-up's garbage once and
freezes what survives: those objects live as long as the process, and later collections no
longer walk them. A bridge embedded in a program of its own (``main()`` called directly) never
pauses the collector, and resuming it then does nothing.

The entry points also keep numpy's OpenBLAS to the calling thread (:func:`one_blas_thread`):
at import it starts a server thread per further core, which the bridge never uses (its arrays
are copied, never multiplied), and a fleet's bridge counts every thread.
"""

from __future__ import annotations

import gc
import os
from typing import TYPE_CHECKING

if TYPE_CHECKING:  # the entry points import this module before rclpy
    from ros_gz_bridge_py.ros.bridge_node import BridgeNode

_paused = False


def finish_start_up(node: BridgeNode) -> None:
    """The channels exist: start ``node``'s own services and resume the collector."""
    node.start_services()
    resume_collector()


def one_blas_thread() -> None:
    """OpenBLAS without threads of its own unless the user asked for them (entry points only,
    before anything imports numpy)."""
    os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")


def pause_collector() -> None:
    """Pause the collector until :func:`resume_collector` (entry points only)."""
    global _paused  # noqa: PLW0603 - one process-wide switch, as the collector is
    if gc.isenabled():
        gc.disable()
        _paused = True


def resume_collector() -> None:
    """Collect once, freeze the objects that survive and run the collector again, if
    :func:`pause_collector` paused it; otherwise nothing."""
    global _paused  # noqa: PLW0603
    if _paused:
        _paused = False
        gc.collect()
        gc.freeze()
        gc.enable()

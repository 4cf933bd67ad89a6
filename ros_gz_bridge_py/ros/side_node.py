"""A second rclpy node for the callbacks the main executor must not (or cannot) run.

The bridge's main node is spun by the EventsExecutor, which is fast but runs neither coroutine
callbacks nor subscription callbacks that take rclpy's message info. The side node lives in the
same context and namespace, is spun by a small multi-threaded executor on its own thread, and
hosts:

* service bridges, whose callbacks are coroutines awaiting the Gazebo reply (up to the service
  timeout) without holding a thread or delaying any topic, in a reentrant group;
* the retries of service responses whose client is not discovered yet (``late_responses.py``);
* ROS -> Gazebo subscriptions that need message info to recognise the bridge's own publications
  (bidirectional topics, see ``loop_guard.py``), in the node's default mutually exclusive group
  so each topic keeps its order.
"""

from __future__ import annotations

import threading
from concurrent.futures import ThreadPoolExecutor
from typing import Any

from rclpy.callback_groups import ReentrantCallbackGroup
from rclpy.executors import ExternalShutdownException, MultiThreadedExecutor
from rclpy.impl.implementation_singleton import rclpy_implementation as _rclpy
from rclpy.node import Node as RosNode
from rclpy.parameter import Parameter
from rclpy.task import Future
from rclpy.type_description_service import START_TYPE_DESCRIPTION_SERVICE_PARAM

from ros_gz_bridge_py.ros.late_responses import LateResponses

#: The bridge's helper nodes are named ``_<bridge node>_side`` and ``_<bridge node>_native``
#: (the node no executor spins). The leading underscore makes them hidden nodes, which ROS
#: tools leave out (``ros2 node list`` without ``--all``): users see the one node they started,
#: as with the C++ bridge.
HIDDEN = "_"
#: Longest time one spin step of the side node waits: how long closing waits for its thread.
SPIN_STEP = 0.2
SUFFIX = "_side"
NATIVE_SUFFIX = "_native"


def side_node_name(owner: Any, number: int = 1) -> str:
    """``number``: the bridge's on ``owner`` (``core/node_share.py``); the first has none."""
    return f"{HIDDEN}{owner.get_name()}{SUFFIX}{_numbered(number)}"


def native_node_name(owner: Any, number: int = 1) -> str:
    return f"{HIDDEN}{owner.get_name()}{NATIVE_SUFFIX}{_numbered(number)}"


def _numbered(number: int) -> str:
    return "" if number == 1 else f"_{number}"


def unspun_node(owner: Any, number: int = 1) -> Any:
    """A node beside ``owner`` (same context and namespace) that no executor spins: the
    subscriptions of native ROS -> Gazebo loops live there, so that only those loops take
    their messages (docs/native.md §7)."""
    return _helper_node(native_node_name(owner, number), owner)


def _helper_node(name: str, owner: Any) -> RosNode:
    """A node of the bridge's own beside ``owner``, without the services users' tools ask of
    the bridge's node (parameters, type descriptions): that node offers them. Creating a
    service imports numpy (``ros/bridge_node.py``), which a channel created with this node
    would wait for.

    The process's ROS arguments are not its own: ``-r __node:=NAME`` would rename it too, and
    a remap rule for the bridge's node (``-r ros_gz_bridge:/a:=/b``) would not reach it. Its
    endpoints take the names the bridge's node resolves (every rule the user wrote for it), in
    the bridge's namespace.
    """
    return RosNode(
        name,
        namespace=owner.get_namespace(),
        context=owner.context,
        use_global_arguments=False,
        start_parameter_services=False,
        parameter_overrides=[Parameter(START_TYPE_DESCRIPTION_SERVICE_PARAM, value=False)],
    )


class SideNode:
    """The side node of one bridge and the thread that spins it."""

    THREADS = 4

    def __init__(self, owner: Any, number: int = 1) -> None:
        """``number``: the bridge's on ``owner`` (:func:`side_node_name`)."""
        #: The bridge's node, whose name the bridge's log lines carry.
        self.owner = owner
        self.node = _helper_node(side_node_name(owner, number), owner)
        self.reentrant = ReentrantCallbackGroup()
        self.late_responses = LateResponses(self.node)
        self._executor = MultiThreadedExecutor(num_threads=self.THREADS, context=owner.context)
        self._executor.add_node(self.node)
        self._closing = False
        self._thread = threading.Thread(target=self._spin, name="ros-gz-side", daemon=True)
        self._thread.start()

    def future(self) -> Future:
        """A future that resumes a coroutine callback of this node awaiting it when it is done,
        whichever thread completes it.

        rclpy resumes a waiting coroutine only when its executor wakes; scheduling a done
        callback is what wakes it, so every future made here has one.
        """
        future = Future(executor=self._executor)
        future.add_done_callback(_resume)
        return future

    def _spin(self) -> None:
        """Spin until closed. rclpy raises InvalidHandle into the spinning thread when an
        entity it waits on is destroyed from another thread (a bridge removed while messages
        flow): that ended this thread, and every later service and loop-guarded channel
        carried nothing without a word; the entity is gone, so spinning goes on."""
        context = self.owner.context
        while not self._closing and context.ok():
            try:
                self._executor.spin_once(timeout_sec=SPIN_STEP)
            except ExternalShutdownException:
                return
            except _rclpy.InvalidHandle:
                continue

    def close(self) -> None:
        self._closing = True
        self._executor.shutdown(timeout_sec=1.0)
        self._thread.join(timeout=2.0)
        # rclpy's MultiThreadedExecutor leaves its worker pool running after shutdown():
        # without this, each closed bridge left its idle worker threads behind.
        pool = getattr(self._executor, "_executor", None)
        if isinstance(pool, ThreadPoolExecutor):
            pool.shutdown(wait=True)
        self.node.destroy_node()


def _resume(_future: Future) -> None:
    """A done callback whose only job is to be scheduled (see :meth:`SideNode.future`)."""

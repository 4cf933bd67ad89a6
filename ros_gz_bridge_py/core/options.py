"""The node-wide options of a :class:`~ros_gz_bridge_py.core.bridge.Bridge`.

The bridge and its channels read their settings here and nowhere else; in particular they read
no environment variable. The executables turn their node parameters and ``ROS_GZ_BRIDGE_*``
switches into these options (:mod:`ros_gz_bridge_py.app.settings`); a program that embeds the
bridge passes its own.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from ros_gz_bridge_py.config.gz_version import GARDEN
from ros_gz_bridge_py.core.diagnosis import ENTRY_QOS_SETTING
from ros_gz_bridge_py.core.services import DEFAULT_TIMEOUT
from ros_gz_bridge_py.errors import ConfigError
from ros_gz_bridge_py.transport.delivery import MAX_QUEUED_BYTES

#: How much lower the CPU priority (nice) of bulk-path delivery threads is, by default.
BULK_THREAD_NICE = 10


@dataclass(frozen=True)
class BridgeOptions:
    """Node-wide settings (the C++ node parameters of the same names, and how messages travel)."""

    lazy: bool = False
    heartbeat: float = 1.0
    override_timestamps_with_wall_time: bool = False
    override_frame_id: str = ""
    service_timeout: float = DEFAULT_TIMEOUT
    #: Images and point clouds on the bulk path (False: protobuf and rclpy message objects).
    bulk_path: bool = True
    #: Bulk path: publish serialized messages through rcl with the GIL released (False: through
    #: rclpy's own publish, GIL held).
    rcl_serialized_publish: bool = True
    #: Nice offset of bulk-path delivery threads (0 keeps their priority).
    bulk_nice: int = BULK_THREAD_NICE
    #: ROS->Gazebo channels read serialized messages with ros_cdr (False: rclpy's objects).
    light_read: bool = True
    #: Gazebo->ROS channels of small messages serialize with ``cdr_writer`` and publish the
    #: bytes with the GIL released (False: rclpy's publish of the message object).
    cdr_write: bool = True
    #: Gazebo->ROS channels of pairs a native program expresses run their per-message loop in
    #: the native extension where it is built (docs/native.md; False: the Python path).
    native: bool = True
    #: The simulator's Gazebo line when the user names it (``gz_version``, ``GZ_VERSION``);
    #: only ``garden`` changes anything: its ``gz.msgs.*`` have Fortress layouts and names.
    gz_version: str = ""
    #: Evaluate every channel and log why it carries nothing (``explain.py``).
    explain: bool = True
    #: Messages per second a channel passes at most unless its entry says (0: no limit).
    max_rate: float = 0.0
    #: Payload bytes each Gazebo->ROS channel's queue holds at most (beyond its count of
    #: messages); past it the oldest are dropped and counted (one message is always kept).
    max_queued_bytes: int = MAX_QUEUED_BYTES
    #: The executable that chose every entry's types ("image_bridge"): explanations then send a
    #: topic of other types to parameter_bridge instead of proposing types it cannot take.
    types_fixed_by: str = ""
    #: What the user changes to set a channel's QoS profile, as explanations name it.
    qos_setting: str = ENTRY_QOS_SETTING

    def __post_init__(self) -> None:
        """Refuse numbers the bridge cannot run with, before anything is opened (a heartbeat
        of 0 was a timer spinning a core; a negative one rcl's raw error).

        Raises:
            ConfigError: the first such field, named with what it takes.
        """
        checks = (
            ("heartbeat", self.heartbeat > 0, "seconds between lazy re-checks, > 0 (1.0)"),
            ("service_timeout", self.service_timeout > 0, "seconds, > 0"),
            ("max_rate", self.max_rate >= 0, "messages per second, 0 for no limit"),
            ("max_queued_bytes", self.max_queued_bytes >= 1, "bytes, at least 1"),
        )
        for name, fine, takes in checks:
            value = getattr(self, name)
            if not fine or not math.isfinite(value):
                msg = f"BridgeOptions({name}={value!r}): give {takes}"
                raise ConfigError(msg)

    @property
    def garden(self) -> bool:
        return self.gz_version == GARDEN

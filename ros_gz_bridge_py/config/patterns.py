"""Entries that discovery completes: wildcard names and left-out types.

A YAML entry whose Gazebo name holds a wildcard, or that leaves out a type, is a
:class:`TopicPattern` instead of a :class:`~ros_gz_bridge_py.config.model.TopicBridgeSpec`:
the running bridge makes one bridge per Gazebo topic of the partition that matches it, as
such topics appear, with the type discovery shows (docs/many-topics.md, "Templates and wildcards").

Wildcards: ``*`` stands for one or more characters within one name token (no ``/``), ``**``
for one or more whole tokens. A ROS name may repeat the wildcards of the Gazebo name, in the
same order: each takes what its partner matched (made a valid ROS name by
:func:`~ros_gz_bridge_py.config.names.ros_name_for_gz`). Without a ROS name, the ROS name is
the matched Gazebo name made valid; a ROS name without wildcards gathers every match on one
ROS topic.
"""

from __future__ import annotations

import dataclasses
import re
from dataclasses import dataclass
from functools import cached_property

from ros_gz_bridge_py.config.model import Direction, TopicBridgeSpec
from ros_gz_bridge_py.config.names import ros_name_for_gz
from ros_gz_bridge_py.errors import ConfigError

_WILDCARD = re.compile(r"\*\*|\*")


def has_wildcard(name: str) -> bool:
    return "*" in name


def wildcards(name: str) -> list[str]:
    """The wildcards of ``name`` in order (``*`` or ``**`` each)."""
    return _WILDCARD.findall(name)


def check_wildcards(gz_name: str, ros_name: str, where: str) -> None:
    """Raises ConfigError unless the ROS name's wildcards are none or the Gazebo name's."""
    for name, key in ((gz_name, "gz_topic_name"), (ros_name, "ros_topic_name")):
        if "***" in name:
            msg = f"Could not parse entry: {key} '{name}' has '***'; use * (within a token) or **"
            raise ConfigError(msg, where)
    ros = wildcards(ros_name)
    if ros and ros != wildcards(gz_name):
        msg = (
            f"Could not parse entry: ros_topic_name '{ros_name}' has the wildcards {ros} but "
            f"gz_topic_name '{gz_name}' has {wildcards(gz_name)}; repeat the Gazebo name's "
            "wildcards in the same order, or write none"
        )
        raise ConfigError(msg, where)


@dataclass(frozen=True)
class TopicPattern:
    """A topic entry completed by discovery; empty types and None values are "not given"."""

    #: "" : the matched Gazebo name, made a valid ROS name.
    ros_topic: str
    gz_topic: str
    ros_type: str = ""
    gz_type: str = ""
    #: None: from discovery (Gazebo publishers: GZ_TO_ROS; only subscribers: ROS_TO_GZ).
    direction: Direction | None = None
    lazy: bool | None = None
    publisher_queue: int | None = None
    subscriber_queue: int | None = None
    qos_profile: str | None = None
    frame_id: str | None = None
    max_rate: float | None = None
    source: str = ""

    @classmethod
    def from_spec(cls, spec: TopicBridgeSpec, direction: Direction | None) -> TopicPattern:
        """The pattern of an entry read as ``spec`` (its direction None when not given)."""
        values = {f.name: getattr(spec, f.name) for f in dataclasses.fields(cls)}
        return cls(**{**values, "direction": direction})

    def completed(
        self, ros_topic: str, gz_topic: str, types: tuple[str, str], direction: Direction
    ) -> TopicBridgeSpec:
        """The entry this pattern makes of one discovered topic (``types``: ROS, Gazebo): its
        own settings, the rest completed."""
        values = {f.name: getattr(self, f.name) for f in dataclasses.fields(self)}
        ros_type, gz_type = types
        return TopicBridgeSpec(**{
            **values, "ros_topic": ros_topic, "gz_topic": gz_topic,
            "ros_type": ros_type, "gz_type": gz_type, "direction": direction,
        })  # fmt: skip

    @cached_property
    def _regex(self) -> re.Pattern[str]:
        parts = _WILDCARD.split(self.gz_topic)
        found = wildcards(self.gz_topic)
        text = re.escape(parts[0])
        for wildcard, part in zip(found, parts[1:], strict=True):
            text += ("(.+)" if wildcard == "**" else "([^/]+)") + re.escape(part)
        return re.compile(text)

    def match(self, gz_topic: str) -> tuple[str, ...] | None:
        """What each wildcard matched in ``gz_topic`` (() for a plain name); None if no match."""
        found = self._regex.fullmatch(gz_topic)
        return None if found is None else found.groups()

    def ros_name(self, gz_topic: str, captures: tuple[str, ...]) -> str:
        """The ROS name of the matched ``gz_topic``."""
        if not self.ros_topic:
            return ros_name_for_gz(gz_topic)
        parts = _WILDCARD.split(self.ros_topic)
        if len(parts) == 1:
            return self.ros_topic
        name = parts[0]
        for capture, part in zip(captures, parts[1:], strict=True):
            name += ros_name_for_gz(capture).lstrip("/") + part
        return name

"""Names: ROS name expansion, applied to Gazebo topic names when ``expand_gz_topic_names`` is
set, and the ROS name discovered bridging gives a Gazebo topic.

Expansion follows rcl's rules (``rcl_expand_topic_name``): absolute names are unchanged,
relative names get the namespace, ``~`` is the node's private namespace, ``{node}`` and
``{ns}``/``{namespace}`` are substituted. Name validation beyond that is left to rclpy.
"""

from __future__ import annotations

import re

from ros_gz_bridge_py.errors import ConfigError

#: What a ROS name may hold, as fixes say it (rcl's own errors name only the rule broken).
ROS_NAME_RULE = (
    "a ROS name is letters, digits and underscores between its '/' (no '-', '.' or spaces)"
)


def _normalise_namespace(namespace: str) -> str:
    stripped = namespace.strip("/")
    return f"/{stripped}" if stripped else ""


def expand_topic_name(name: str, namespace: str, node_name: str) -> str:
    """Expand ``name`` as a topic of node ``node_name`` in ``namespace``.

    >>> expand_topic_name("scan", "/robot1", "bridge")
    '/robot1/scan'
    >>> expand_topic_name("~/status", "/", "bridge")
    '/bridge/status'
    """
    if not name:
        msg = "cannot expand an empty topic name"
        raise ConfigError(msg)
    ns = _normalise_namespace(namespace)
    if name.startswith("~"):
        if name != "~" and not name.startswith("~/"):
            msg = f"topic name '{name}': '~' must be followed by '/'"
            raise ConfigError(msg)
        name = f"{ns}/{node_name}{name[1:]}"
    name = name.replace("{node}", node_name)
    name = name.replace("{namespace}", ns or "/").replace("{ns}", ns or "/")
    if name.startswith("//"):  # "{ns}/x" in the root namespace
        return name[1:]
    if name.startswith("/"):
        return name
    return f"{ns}/{name}"


#: Characters a ROS name token may hold (rmw's topic name rules); the rest become ``_``.
_NOT_IN_ROS_NAMES = re.compile(r"[^A-Za-z0-9_]")


def ros_name_for_gz(gz_topic: str) -> str:
    """The ROS topic name discovered bridging gives a Gazebo topic (docs/many-topics.md,
    "Discovered bridging"): ``::`` (Gazebo's scope separator) becomes ``/``; every other character
    that ROS names do not allow (``-``, ``.``, ``:``, ...) becomes ``_``; a token that starts with
    a digit gets a leading ``_``; empty tokens go. A leading ``/`` is kept; "" when nothing
    is left.

    >>> ros_name_for_gz("/model/my-robot::base_link/3d_scan")
    '/model/my_robot/base_link/_3d_scan'
    """
    tokens = []
    for written in gz_topic.replace("::", "/").split("/"):
        token = _NOT_IN_ROS_NAMES.sub("_", written)
        if token:
            tokens.append(f"_{token}" if token[0].isdigit() else token)
    name = "/".join(tokens)
    return f"/{name}" if name and gz_topic.startswith("/") else name


def renamed(given: str, resolved: str) -> bool:
    """True when ROS resolution changed ``given`` into ``resolved`` beyond the leading ``/`` a
    relative name gets in the root namespace (a namespace, ``~`` or a remapping did).

    >>> renamed("scan", "/scan"), renamed("scan", "/robot1/scan")
    (False, True)
    """
    return resolved not in (given, f"/{given}")

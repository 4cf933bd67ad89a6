"""ROS name expansion, applied to Gazebo topic names when ``expand_gz_topic_names`` is set.

Follows rcl's rules (``rcl_expand_topic_name``): absolute names are unchanged, relative names
get the namespace, ``~`` is the node's private namespace, ``{node}`` and ``{ns}``/``{namespace}``
are substituted. Name validation beyond that is left to rclpy.
"""

from __future__ import annotations

from ros_gz_bridge_py.errors import ConfigError


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

"""The ``gz_version`` setting: which Gazebo line the simulator is, when the user says so.

The bridge meets every line on its own terms without being told (docs/protocol-lines.md §9), with
one exception it cannot detect: Garden sends ``gz.msgs.IMU`` in the Fortress layout and, like
Fortress, announces no record in its heartbeats. ``gz_version:=garden`` (or ``GZ_VERSION=garden``,
the variable ros_gz builds with) says so. The other names are accepted and change nothing.
"""

from __future__ import annotations

from ros_gz_bridge_py.errors import ConfigError

#: The environment variable ros_gz builds with; the default of the ``gz_version`` parameter.
GZ_VERSION_ENV = "GZ_VERSION"
GARDEN = "garden"
#: Gazebo lines by their release names, oldest first.
KNOWN_LINES = ("citadel", "fortress", GARDEN, "harmonic", "ionic", "jetty")


def check_gz_version(value: str) -> str:
    """``value`` lower-cased if it names a Gazebo line ('' = not said).

    Raises:
        ConfigError: an unknown name.
    """
    name = value.strip().lower()
    if name and name not in KNOWN_LINES:
        msg = (
            f"gz_version {value!r} is not a Gazebo release; use one of {', '.join(KNOWN_LINES)} "
            "(only 'garden' changes how messages are read), or leave it empty"
        )
        raise ConfigError(msg)
    return name

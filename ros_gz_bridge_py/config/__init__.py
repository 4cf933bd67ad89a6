"""Every way users configure bridges, parsed into frozen values with located errors.

Sources: ``parameter_bridge`` arguments (:func:`parse_cli_args`), YAML files
(:func:`read_yaml_file`, :func:`parse_yaml`) and ``bridge_names`` + ``bridges.<name>.*``
parameters (:func:`parse_parameter_bridges`). Each returns a :class:`ParseResult`; only the
caller logs, skips or fails. Nothing here imports rclpy or logs.

Differences from the C++ ``ros_gz_bridge`` (Jazzy):

============================================  =====================================================
C++                                           ros_gz_bridge_py
============================================  =====================================================
CLI: a bad argument prints the whole usage    ``UsageError`` names the argument (position and
and names nothing                             text), what is wrong and what to write
CLI: ``name@pkg/msg/T`` (no direction, no     ``UsageError`` "no Gazebo type; write
Gazebo type) is a silent no-op                name@pkg/msg/T@gz.msgs.X ..."
CLI: ``t@@x``, ``t@[x`` are silent no-ops,    ``UsageError`` "no ROS type after the first '@'"
``t@`` prints usage
CLI: ``/x@foo/srv/Bar`` prints a garbled      parses to a ``ServiceBridgeSpec``; the converter
line on stderr                                registry rejects the type, listing the supported
                                              services
CLI: ``std_msgs/String`` fails type lookup    kept, plus a warning "did you mean
later                                         std_msgs/msg/String"
CLI: ``a@T[x@y`` silently gets the ROS type   same parse, plus a warning about the stray ``[``
``T[x``
YAML: ``publisher_queue: abc``, ``lazy:       one ``ConfigError`` at the value's line (e.g. "Could
maybe``, a map where a string is expected or  not parse entry: lazy must be true or false, got
a negative queue throws; the process dies     'maybe'"); that entry is skipped, the others load
YAML: a syntax error throws; the process      "Could not parse config: invalid YAML: <problem>" at
dies                                          its line; no bridges from that file
YAML: unknown keys are ignored silently       a warning with a did-you-mean hint
YAML: an entry with no topic name gets empty  "Could not parse entry: one of topic_name,
names and fails later in rclcpp               ros_topic_name or gz_topic_name must be set"
YAML: a null value (``topic_name:``) goes     counts as not set, like the empty string
through yaml-cpp's string conversion
YAML: the file is re-read and its errors      parsed once per call; the caller decides when to
re-logged every heartbeat                     re-read
YAML: a key written twice                     the last one wins, with a warning (none for a key
                                              an entry sets over its ``<<`` merge)
YAML: ``ign_topic_name``/``ign_type_name``    accepted with a deprecation warning, so Humble files
and ``IGN_TO_ROS``/``ROS_TO_IGN`` are         keep working
Humble-only
YAML: ``service_name`` with only one of the   error "set both gz_req_type_name and
two Gazebo types                              gz_rep_type_name, or neither"
YAML: unknown ``qos_profile``                 "Could not parse entry: invalid qos_profile [X]; use
                                              one of ..."
YAML: ``<<: *anchor`` merge keys              merged by PyYAML's rules (shared settings for several
                                              entries)
YAML: a missing type is "both ros_type_name   a :class:`TopicPattern` completed by discovery, as
and gz_type_name must be set"                 is an entry with a wildcard (``patterns.py``)
YAML, CLI: no placeholders                    ``${NAME}``, one entry per value (``templates.py``)
YAML, params: no rate limit                   ``max_rate`` (Hz, 0: none)
YAML, params: any ``size_t`` queue depth is   above 16777216 (``MAX_QUEUE_DEPTH``): an error
passed to rclcpp                              "publisher_queue must be at most 16777216, got N"
YAML, params: a queue of 0 gets rclcpp's      kept, with a warning naming the entry: 0 is the
warning, which names no entry                 middleware's default depth, not unbounded
Params: direction ``NONE`` creates nothing,   the bridge is skipped with a warning
silently
Params: any negative queue means "default"    only -1 (or unset) means default; other negatives are
                                              an error
Params: ``"true"``/``"5"`` strings (launch    accepted for ``lazy`` and the queues
``bridge_params``) are parameter type errors
============================================  =====================================================

The error texts the C++ tests assert (``Could not parse entry: ...``, ``Could not parse
config: ...``, ``Bridge <name> ...``) are kept verbatim in ``ConfigError.message``; the location
(``"<file> entry <n> (line <l>)"``, ``"argument <n> '<text>'"``, ``"parameter bridges.<name>"``)
is in ``ConfigError.source``.
"""

from __future__ import annotations

from ros_gz_bridge_py.config.cli import USAGE, parse_cli_args
from ros_gz_bridge_py.config.model import (
    QOS_PROFILE_NAMES,
    BridgeSpec,
    Direction,
    ParseResult,
    ServiceBridgeSpec,
    TopicBridgeSpec,
    UsageError,
)
from ros_gz_bridge_py.config.names import expand_topic_name
from ros_gz_bridge_py.config.params import parse_parameter_bridges
from ros_gz_bridge_py.config.patterns import TopicPattern
from ros_gz_bridge_py.config.yaml_file import parse_yaml, read_yaml_file

__all__ = [
    "QOS_PROFILE_NAMES",
    "USAGE",
    "BridgeSpec",
    "Direction",
    "ParseResult",
    "ServiceBridgeSpec",
    "TopicBridgeSpec",
    "TopicPattern",
    "UsageError",
    "expand_topic_name",
    "parse_cli_args",
    "parse_parameter_bridges",
    "parse_yaml",
    "read_yaml_file",
]

"""``bridge_types``: list the supported ROS <=> Gazebo type pairs, like the C++ tool.

Options and their texts and exit codes follow docs/behaviour.md §1.2: one option per run, its
argument second. Differences: each pair is listed once (with its ``gz.msgs.X`` name;
``ignition.msgs.X`` is accepted wherever a Gazebo type is read), types are listed once each
and sorted, services get their own heading, ``--json`` prints everything as one JSON document,
why pairs are missing from a listing or a failed lookup (a converter module that could not
load) is said once per reason on stderr, and arguments after the option are refused with one
line (exit 1) where C++ ignores them.
"""

from __future__ import annotations

import json
import sys
from collections.abc import Sequence
from typing import TextIO

from ros_gz_bridge_py.converters.registry import Registry, build_registry
from ros_gz_bridge_py.native.channel import expressible

USAGE = """\
usage: bridge_types [OPTION [TYPE]]

  -h, --help               show this help and exit
  --print-pairs            list the supported ROS <=> Gazebo message and service pairs
  --print-ros              list the supported ROS message types
  --print-gz               list the supported Gazebo message types
  --get-ros-to-gz TYPE     print the default Gazebo type for ROS TYPE
  --get-gz-to-ros TYPE     print the default ROS type for Gazebo TYPE (gz.msgs.X or ignition.msgs.X)
  --json                   print all pairs and services as one JSON document

Gazebo types are written gz.msgs.X; ignition.msgs.X names the same message. Either
spelling, in any configuration, matches Gazebo peers of every line: Fortress publishes and
subscribes ignition.msgs.X, Garden and later gz.msgs.X, and the bridge puts on the wire the
spelling each peer takes (IMU messages in that line's layout).
"""

PAIRS_HEADING = "Supported ROS <=> Gazebo message type conversion pairs:"
SERVICES_HEADING = "Supported ROS <=> Gazebo service type pairs:"


def _print_pairs(registry: Registry, out: TextIO) -> None:
    print(PAIRS_HEADING, file=out)
    for pair in registry.pairs:
        print(f"  - '{pair.ros_type}' (ROS) <=> '{pair.gz_type}' (GZ)", file=out)
    print(SERVICES_HEADING, file=out)
    for service in registry.services:
        print(
            f"  - '{service.ros_type}' (ROS) <=> "
            f"'{service.gz_req_type}' -> '{service.gz_rep_type}' (GZ)",
            file=out,
        )


def _as_json(registry: Registry) -> str:
    # Per direction, whether the native data plane carries the pair (docs/native.md), or why not.
    to_ros, to_gz = expressible(registry.pairs)
    document = {
        "pairs": [
            {
                "ros_type": p.ros_type,
                "gz_type": p.gz_type,
                "origin": p.origin,
                "native_to_ros": not to_ros[(p.ros_type, p.gz_type)],
                "native_to_gz": not to_gz[(p.ros_type, p.gz_type)],
                "python_to_ros_because": to_ros[(p.ros_type, p.gz_type)],
                "python_to_gz_because": to_gz[(p.ros_type, p.gz_type)],
            }
            for p in registry.pairs
        ],
        "services": [
            {
                "ros_type": s.ros_type,
                "gz_request_type": s.gz_req_type,
                "gz_reply_type": s.gz_rep_type,
                "origin": s.origin,
            }
            for s in registry.services
        ],
        "unavailable": dict(registry.unavailable),
    }
    return json.dumps(document, indent=2)


def _report_unavailable(registry: Registry, err: TextIO) -> None:
    """Why pairs are missing from a listing or a lookup: each reason once (a package's
    several converter modules fail for one reason)."""
    for reason in dict.fromkeys(registry.unavailable.values()):
        print(f"bridge_types: not listed: {reason}", file=err)


def _extra_arguments_problem(used: Sequence[str], extra: Sequence[str]) -> str:
    """The line for arguments after the one option (and its TYPE), which the tool used to
    ignore without a word (``--print-pairs --json`` printed text)."""
    extras = " ".join(extra)
    return (
        f"bridge_types: unexpected {extras!r} after {' '.join(used)!r}: give one option per run "
        "(--json alone prints every pair and service as JSON; bridge_types -h lists the options)"
    )


def main(argv: Sequence[str] | None = None) -> int:
    """Run the tool on ``argv`` (without the program name); return the exit code."""
    args = list(sys.argv[1:] if argv is None else argv)
    out, err = sys.stdout, sys.stderr
    if not args:
        return 0
    option = args[0]
    if option in ("-h", "--help"):
        print(USAGE, end="", file=out)
        return 0
    lookups = {"--get-ros-to-gz": "get-ros-to-gz", "--get-gz-to-ros": "--get-gz-to-ros"}
    if option in lookups and len(args) < 2:
        print(f"{lookups[option]} requires an argument", file=err)
        return 1
    listings = ("--print-pairs", "--print-ros", "--print-gz", "--json")
    if option not in listings and option not in lookups:
        print(f"bridge_types: unknown option {option!r}\n{USAGE}", end="", file=err)
        return 1
    taken = 2 if option in lookups else 1
    if len(args) > taken:
        print(_extra_arguments_problem(args[:taken], args[taken:]), file=err)
        return 1

    registry = build_registry()
    if option in listings:
        _report_unavailable(registry, err)
    if option == "--print-pairs":
        _print_pairs(registry, out)
    elif option == "--print-ros":
        print(*sorted({p.ros_type for p in registry.pairs}), sep="\n", file=out)
    elif option == "--print-gz":
        print(*sorted({p.gz_type for p in registry.pairs}), sep="\n", file=out)
    elif option == "--json":
        print(_as_json(registry), file=out)
    else:
        wanted = args[1]
        if option == "--get-ros-to-gz":
            found, listing = registry.gz_types_for(wanted), "--print-ros"
        else:
            found, listing = registry.ros_types_for(wanted), "--print-gz"
        if not found:
            _report_unavailable(registry, err)
            print(f"Type [{wanted}] has no mapping, use {listing} to see supported types", file=err)
            return 1
        print(found[0], file=out)
    return 0


if __name__ == "__main__":
    sys.exit(main())

"""The table of ROS <-> Gazebo message pairs, built from data declared by each module.

How to add a pair or write a converter module: ``CONVENTIONS.md`` at the repository root.

A converter module declares a module-level ``PAIRS`` tuple of :class:`Pair` (topics) and
optionally ``SERVICES`` of :class:`ServicePair`. The registry imports every module of this
package (see :func:`modules_of`; those that declare neither are helpers and add nothing),
then every module registered under the entry-point group ``ros_gz_bridge_py.converters``, and
indexes their pairs by (ROS type, Gazebo type).

Gazebo type names are accepted as ``gz.msgs.X`` or ``ignition.msgs.X``. An exact registration
wins (``ignition.msgs.IMU`` has its own, Fortress wire layout); otherwise the name is
normalised to ``gz.msgs.X``. The default Gazebo type for a ROS type is the first pair declared
for it (all of them are in its package's module). The default ROS type for a Gazebo type is the
first pair declared for it too, unless one is marked ``default_for_gz_type``: where modules of
this package pair one Gazebo type with ROS types of different packages, the default is marked,
so that it does not depend on the order modules are read in (by name, then plugins).
"""

from __future__ import annotations

import dataclasses
import functools
import importlib
import itertools
import pkgutil
from collections.abc import Callable, Iterable, Iterator
from dataclasses import dataclass, field
from importlib.metadata import entry_points
from types import ModuleType
from typing import TYPE_CHECKING, Any

from ros_gz_bridge_py.errors import BridgeError, UnsupportedTypeError
from ros_gz_bridge_py.msgs.names import Spelling, canonical_type, respell, spelling_of, spellings

if TYPE_CHECKING:
    from ros_gz_bridge_py.bulk.path import BulkPath

ENTRY_POINT_GROUP = "ros_gz_bridge_py.converters"
_PACKAGE = __name__.rpartition(".")[0]


@dataclass(frozen=True)
class Pair:
    """One ROS message type and one Gazebo message type with both conversions.

    ``to_gz`` takes a ROS message and returns a new gz protobuf message; ``to_ros`` takes a
    gz protobuf message and returns a new ROS message. Either raises
    :class:`~ros_gz_bridge_py.errors.ConversionError` for data it cannot convert.
    """

    ros_type: str
    gz_type: str
    to_gz: Callable[[Any], Any]
    to_ros: Callable[[Any], Any]
    ros_class: type[Any]
    #: Where it came from (module name), for listings and error messages.
    origin: str = field(default="", compare=False)
    #: For large messages: how channels convert them without copying the bulk bytes around.
    bulk: BulkPath | None = field(default=None, compare=False)
    #: This pair's ROS type is the default for its Gazebo type, which other modules pair too.
    default_for_gz_type: bool = field(default=False, compare=False)

    @classmethod
    def of(
        cls,
        ros_class: type[Any],
        gz_type: str,
        to_gz: Callable[[Any], Any],
        to_ros: Callable[[Any], Any],
        *,
        bulk: BulkPath | None = None,
        default_for_gz_type: bool = False,
    ) -> Pair:
        """The pair for ``ros_class``, whose ROS type name (``pkg/msg/Name``) it bears."""
        ros_type = f"{_package_of(ros_class)}/msg/{ros_class.__name__}"
        return cls(
            ros_type,
            gz_type,
            to_gz,
            to_ros,
            ros_class,
            bulk=bulk,
            default_for_gz_type=default_for_gz_type,
        )


@dataclass(frozen=True)
class ServicePair:
    """A ROS service type bridged to one Gazebo service (request type, reply type).

    ``request_to_gz`` takes the ROS request and returns the gz request message;
    ``reply_to_ros`` takes the gz reply message and returns a new ROS response.
    ``failure_to_ros`` returns the ROS response sent when Gazebo reports failure or times out.
    """

    ros_type: str
    gz_req_type: str
    gz_rep_type: str
    request_to_gz: Callable[[Any], Any]
    reply_to_ros: Callable[[Any], Any]
    failure_to_ros: Callable[[], Any]
    ros_class: type[Any]
    origin: str = field(default="", compare=False)


@dataclass
class Registry:
    """All known pairs, indexed for lookup. Registering a duplicate pair raises."""

    pairs: list[Pair] = field(default_factory=list)
    services: list[ServicePair] = field(default_factory=list)
    #: Modules that could not be imported (e.g. an interface package not built): name -> reason.
    unavailable: dict[str, str] = field(default_factory=dict)
    _by_key: dict[tuple[str, str], Pair] = field(default_factory=dict, repr=False)
    _services_by_type: dict[str, ServicePair] = field(default_factory=dict, repr=False)

    def add(self, pair: Pair) -> None:
        key = (pair.ros_type, pair.gz_type)
        if key in self._by_key:
            msg = f"pair {pair.ros_type} <-> {pair.gz_type} registered twice ({pair.origin})"
            raise BridgeError(msg)
        self._by_key[key] = pair
        self.pairs.append(pair)

    def add_service(self, pair: ServicePair) -> None:
        if pair.ros_type in self._services_by_type:
            msg = f"service {pair.ros_type} registered twice ({pair.origin})"
            raise BridgeError(msg)
        self._services_by_type[pair.ros_type] = pair
        self.services.append(pair)

    def add_module(self, module: ModuleType, origin: str) -> None:
        for pair in getattr(module, "PAIRS", ()):
            self.add(_with_origin(pair, origin))
        for service in getattr(module, "SERVICES", ()):
            self.add_service(_with_origin(service, origin))

    def find(self, ros_type: str, gz_type: str) -> Pair | None:
        """The pair for exactly these names, accepting both Gazebo prefixes."""
        pair = self._by_key.get((ros_type, gz_type))
        if pair is None:
            pair = self._by_key.get((ros_type, canonical_type(gz_type)))
        return pair

    def get(self, ros_type: str, gz_type: str) -> Pair:
        """Like :meth:`find`, but raise :class:`UnsupportedTypeError` naming the fix."""
        pair = self.find(ros_type, gz_type)
        if pair is not None:
            return pair
        raise UnsupportedTypeError(self._explain_missing(ros_type, gz_type))

    def layouts(self, ros_type: str, gz_type: str, *, garden: bool = False) -> dict[str, Pair]:
        """The pair that reads and writes each spelling of ``gz_type`` on the wire.

        The spellings share one pair, except where the layout differs by Gazebo line (the
        IMU: ``ignition.msgs.IMU`` is the Fortress layout). ``garden``: the simulator is
        Garden, whose ``gz.msgs.*`` messages have the Fortress layout.

        Raises:
            UnsupportedTypeError: the pair does not exist.
        """
        layouts = {}
        for name in spellings(gz_type):
            layout = respell(name, Spelling.IGNITION) if garden else name
            layouts[name] = self.get(ros_type, layout)
        return layouts

    def get_service(self, ros_type: str) -> ServicePair:
        service = self._services_by_type.get(ros_type)
        if service is not None:
            return service
        known = ", ".join(sorted(self._services_by_type)) or "none"
        msg = f"service type [{ros_type}] is not supported; supported: {known}"
        raise UnsupportedTypeError(msg)

    def gz_types_for(self, ros_type: str) -> list[str]:
        return [p.gz_type for p in self.pairs if p.ros_type == ros_type]

    def ros_types_for(self, gz_type: str) -> list[str]:
        """The ROS types paired with ``gz_type``, its default first."""
        pairs = [p for p in self.pairs if p.gz_type == gz_type]
        if not pairs:
            canonical = canonical_type(gz_type)
            pairs = [p for p in self.pairs if p.gz_type == canonical]
        pairs.sort(key=lambda pair: not pair.default_for_gz_type)
        return [p.ros_type for p in pairs]

    def _explain_missing(self, ros_type: str, gz_type: str) -> str:
        text = f"no converter for ROS type [{ros_type}] and Gazebo type [{gz_type}]"
        if "/" in ros_type and "/msg/" not in ros_type and "/srv/" not in ros_type:
            pkg, _, name = ros_type.partition("/")
            return f"{text}; ROS types are written in full: did you mean [{pkg}/msg/{name}]?"
        if spelling_of(gz_type) is None:
            return f"{text}; Gazebo types are written gz.msgs.X (or ignition.msgs.X)"
        pkg = ros_type.split("/", 1)[0]
        if pkg in self.unavailable:
            return f"{text}; converters for {pkg} could not load: {self.unavailable[pkg]}"
        gz_options = self.gz_types_for(ros_type)
        if gz_options:
            return f"{text}; [{ros_type}] pairs with: {', '.join(gz_options)}"
        ros_options = self.ros_types_for(gz_type)
        if ros_options:
            return f"{text}; [{gz_type}] pairs with: {', '.join(ros_options)}"
        return f"{text}; run `bridge_types --print-pairs` to list the supported pairs"


def _package_of(ros_class: type[Any]) -> str:
    """``std_msgs`` for ``std_msgs.msg.Bool`` (whose module is ``std_msgs.msg._bool``)."""
    return ros_class.__module__.split(".", 1)[0]


def _with_origin(item: Any, origin: str) -> Any:
    if not isinstance(item, Pair | ServicePair):
        msg = f"{origin}: expected Pair or ServicePair, got {type(item).__name__}"
        raise BridgeError(msg)
    return item if item.origin else dataclasses.replace(item, origin=origin)


def modules_of(package: str) -> list[tuple[str, Callable[[], ModuleType]]]:
    """The public modules of ``package``, by name, each with the call that imports it.

    Which of them are converter modules is known once imported: those that declare ``PAIRS``
    or ``SERVICES``; the others (helpers, this registry) add nothing.
    """
    names = sorted(
        info.name
        for info in pkgutil.iter_modules(importlib.import_module(package).__path__)
        if not info.name.startswith("_")
    )
    return [
        (name, functools.partial(importlib.import_module, f"{package}.{name}")) for name in names
    ]


def _plugin_modules() -> Iterator[tuple[str, Callable[[], ModuleType]]]:
    for ep in entry_points(group=ENTRY_POINT_GROUP):
        yield ep.name, ep.load


def build_registry(
    modules: Iterable[tuple[str, Callable[[], ModuleType]]] | None = None,
) -> Registry:
    """Import ``modules`` (by default this package's, then the plugins) and index their pairs.

    A module that fails to import (its ROS interface package is not installed) is recorded in
    :attr:`Registry.unavailable` instead of failing the whole registry.
    """
    if modules is None:
        modules = itertools.chain(modules_of(_PACKAGE), _plugin_modules())
    registry = Registry()
    for name, load in modules:
        try:
            module = load()
        except ImportError as err:
            registry.unavailable[name] = str(err)
            continue
        registry.add_module(module, name)
    return registry


_DEFAULT: Registry | None = None


def default_registry() -> Registry:
    """The process-wide registry, built on first use."""
    global _DEFAULT  # noqa: PLW0603 - a lazily built process-wide cache
    if _DEFAULT is None:
        _DEFAULT = build_registry()
    return _DEFAULT

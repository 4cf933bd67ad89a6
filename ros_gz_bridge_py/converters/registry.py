"""The table of ROS <-> Gazebo message pairs, built from data declared by each module.

How to add a pair or write a converter module: ``CONVENTIONS.md`` at the repository root.

A converter module declares a module-level ``PAIRS`` tuple of :class:`Pair` (topics) and
optionally ``SERVICES`` of :class:`ServicePair`. The registry imports every module of this
package (see :func:`modules_of`; those that declare neither are helpers and add nothing),
then every module registered under the entry-point group ``ros_gz_bridge_py.converters``, and
indexes their pairs by (ROS type, Gazebo type).

The process-wide registry (:func:`default_registry`) imports them on demand: a module of
this package is named after the ROS package of every type it pairs (a test checks it), so a
lookup of one pair first imports that package's module only; a lookup it does not answer, and
every listing, imports the rest (plugins too) and gives what importing everything at once
gives. A bridge of a few topics thus imports the converters, ROS message packages and numpy
it uses, not all of them.

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
import threading
from collections.abc import Callable, Iterable, Iterator
from dataclasses import dataclass, field
from types import ModuleType
from typing import TYPE_CHECKING, Any

from ros_gz_bridge_py.errors import BridgeError, UnsupportedTypeError
from ros_gz_bridge_py.msgs.names import Spelling, canonical_type, respell, spelling_of, spellings

if TYPE_CHECKING:
    from ros_gz_bridge_py.bulk.path import BulkPath

ENTRY_POINT_GROUP = "ros_gz_bridge_py.converters"
_PACKAGE = __name__.rpartition(".")[0]
#: The ROS interface packages that are not on PyPI: the source tree builds them into a venv
#: (``interfaces/``, ``tools/setup_interfaces.sh``; a test checks the two lists agree).
BUILT_FROM_SOURCE = frozenset(
    {"tf2_msgs", "ros_gz_interfaces", "vision_msgs", "gps_msgs", "actuator_msgs",
     "marine_acoustic_msgs"}
)  # fmt: skip


def why_unavailable(name: str, err: ImportError) -> str:
    """Why converter module ``name`` (named after its ROS package) could not be imported, and
    where the missing package comes from when it is one the source tree builds."""
    missing = (err.name or "").partition(".")[0]
    ours = name == missing or name.startswith(f"{missing}_")  # ros_gz_interfaces_sensors
    if not ours or missing not in BUILT_FROM_SOURCE:
        return str(err)
    dashed = missing.replace("_", "-")
    return (
        f"the ROS interface package {missing} is not installed; build it with "
        f"`tools/setup_interfaces.sh <venv> {missing}` from the source tree (`make setup` builds "
        f"them all), or install ros-jazzy-{dashed} in a ROS install"
    )


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


#: A converter module's name and the call that imports it.
ModuleSource = tuple[str, Callable[[], ModuleType]]


@dataclass
class Registry:
    """All known pairs, indexed for lookup. Registering a duplicate pair raises.

    A registry made by :func:`lazy_registry` holds the modules it has not imported yet:
    :meth:`find` and :meth:`get_service` import the module of the type's ROS package first,
    and everything else imports them all (:meth:`complete`).
    """

    _pairs: list[Pair] = field(default_factory=list, init=False)
    _services: list[ServicePair] = field(default_factory=list, init=False)
    _unavailable: dict[str, str] = field(default_factory=dict, init=False)
    _by_key: dict[tuple[str, str], Pair] = field(default_factory=dict, init=False, repr=False)
    _services_by_type: dict[str, ServicePair] = field(default_factory=dict, init=False, repr=False)
    #: While some modules are not imported (a lazy registry): every module in reading order.
    _sources: Callable[[], Iterable[ModuleSource]] | None = field(
        default=None, init=False, repr=False
    )
    #: The modules a lookup may import alone, by ROS package, until it does.
    _by_package: dict[str, Callable[[], ModuleType]] = field(
        default_factory=dict, init=False, repr=False
    )
    _lock: threading.Lock = field(
        default_factory=threading.Lock, init=False, repr=False, compare=False
    )

    @property
    def pairs(self) -> list[Pair]:
        self.complete()
        return self._pairs

    @property
    def services(self) -> list[ServicePair]:
        self.complete()
        return self._services

    @property
    def unavailable(self) -> dict[str, str]:
        """Modules that could not be imported (e.g. an interface package not built): name ->
        reason."""
        self.complete()
        return self._unavailable

    def complete(self) -> None:
        """Import every module not imported yet; the pairs are then listed in reading order
        (modules by name, then plugins), as if all had been imported at once."""
        with self._lock:
            if self._sources is None:
                return
            full = Registry()
            for name, load in self._sources():  # those imported already are read again
                full.read(name, load)
            # Each index is replaced whole: a lookup meanwhile sees the old or the new one.
            self._by_key = {(pair.ros_type, pair.gz_type): pair for pair in full.pairs}
            self._services_by_type = {service.ros_type: service for service in full.services}
            self._pairs, self._services = full.pairs, full.services
            self._unavailable = full.unavailable
            self._by_package = {}
            self._sources = None

    def _import_package(self, ros_type: str) -> None:
        """Import the module of ``ros_type``'s ROS package, if it is one not imported yet."""
        with self._lock:
            load = self._by_package.pop(ros_type.partition("/")[0], None)
            if load is not None:
                self.read(ros_type.partition("/")[0], load)

    def add(self, pair: Pair) -> None:
        key = (pair.ros_type, pair.gz_type)
        if key in self._by_key:
            msg = f"pair {pair.ros_type} <-> {pair.gz_type} registered twice ({pair.origin})"
            raise BridgeError(msg)
        self._by_key[key] = pair
        self._pairs.append(pair)

    def add_service(self, pair: ServicePair) -> None:
        if pair.ros_type in self._services_by_type:
            msg = f"service {pair.ros_type} registered twice ({pair.origin})"
            raise BridgeError(msg)
        self._services_by_type[pair.ros_type] = pair
        self._services.append(pair)

    @classmethod
    def lazy(
        cls, sources: Callable[[], Iterable[ModuleSource]], alone: Iterable[ModuleSource]
    ) -> Registry:
        """A registry of every module ``sources`` gives, in its order, that imports a module of
        ``alone`` (named after a ROS package) by itself when a lookup of that package needs it.
        """
        registry = cls()
        registry._sources = sources
        registry._by_package = dict(alone)
        return registry

    def read(self, name: str, load: Callable[[], ModuleType]) -> None:
        """Import a module and add its pairs; one that fails to import is recorded in
        :attr:`unavailable`."""
        try:
            module = load()
        except ImportError as err:
            self._unavailable[name] = why_unavailable(name, err)
            return
        self.add_module(module, name)

    def add_module(self, module: ModuleType, origin: str) -> None:
        for pair in getattr(module, "PAIRS", ()):
            self.add(_with_origin(pair, origin))
        for service in getattr(module, "SERVICES", ()):
            self.add_service(_with_origin(service, origin))

    def find(self, ros_type: str, gz_type: str) -> Pair | None:
        """The pair for exactly these names, accepting both Gazebo prefixes."""
        self._import_package(ros_type)
        pair = self._lookup(ros_type, gz_type)
        if pair is None and self._sources is not None:
            self.complete()
            pair = self._lookup(ros_type, gz_type)
        return pair

    def _lookup(self, ros_type: str, gz_type: str) -> Pair | None:
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
        self._import_package(ros_type)
        service = self._services_by_type.get(ros_type)
        if service is None and self._sources is not None:
            self.complete()
            service = self._services_by_type.get(ros_type)
        if service is not None:
            return service
        pkg = ros_type.partition("/")[0]
        if pkg in self.unavailable:
            msg = (
                f"service type [{ros_type}] is not supported here: converters for {pkg} could "
                f"not load: {self.unavailable[pkg]}"
            )
            raise UnsupportedTypeError(msg)
        known = ", ".join(sorted(self._services_by_type)) or "none"
        msg = f"service type [{ros_type}] is not supported; supported: {known}"
        raise UnsupportedTypeError(msg)

    def gz_types_for(self, ros_type: str) -> list[str]:
        """The Gazebo types paired with ``ros_type``, its default first."""
        return [p.gz_type for p in self.pairs if p.ros_type == ros_type]

    def ros_types_for(self, gz_type: str) -> list[str]:
        """The ROS types paired with ``gz_type``, its default first."""
        pairs = [p for p in self.pairs if p.gz_type == gz_type]
        if not pairs:
            canonical = canonical_type(gz_type)
            pairs = [p for p in self.pairs if p.gz_type == canonical]
        pairs.sort(key=lambda pair: not pair.default_for_gz_type)
        return [p.ros_type for p in pairs]

    def ros_service_types_for(self, gz_request: str, gz_reply: str) -> list[str]:
        """The ROS service types whose pair converts to the Gazebo request and reply types
        (either spelling)."""
        wanted = (canonical_type(gz_request), canonical_type(gz_reply))
        return [
            p.ros_type
            for p in self.services
            if (canonical_type(p.gz_req_type), canonical_type(p.gz_rep_type)) == wanted
        ]

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


def modules_of(package: str) -> list[ModuleSource]:
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


def _plugin_modules() -> Iterator[ModuleSource]:
    from importlib.metadata import entry_points  # noqa: PLC0415 - read only when completing

    for ep in entry_points(group=ENTRY_POINT_GROUP):
        yield ep.name, ep.load


def build_registry(modules: Iterable[ModuleSource] | None = None) -> Registry:
    """Import ``modules`` (by default this package's, then the plugins) and index their pairs.

    A module that fails to import (its ROS interface package is not installed) is recorded in
    :attr:`Registry.unavailable` instead of failing the whole registry.
    """
    if modules is None:
        modules = itertools.chain(modules_of(_PACKAGE), _plugin_modules())
    registry = Registry()
    for name, load in modules:
        registry.read(name, load)
    return registry


def lazy_registry(modules: Iterable[ModuleSource] | None = None) -> Registry:
    """A registry of ``modules`` (by default this package's, then the plugins) that imports
    each when a lookup needs it (see :class:`Registry`); it answers as :func:`build_registry`.
    """
    if modules is None:
        local = modules_of(_PACKAGE)
        return Registry.lazy(lambda: itertools.chain(local, _plugin_modules()), local)
    given = list(modules)
    return Registry.lazy(lambda: given, given)


_DEFAULT: Registry | None = None


def default_registry() -> Registry:
    """The process-wide registry (:func:`lazy_registry`), made on first use."""
    global _DEFAULT  # noqa: PLW0603 - a lazily built process-wide cache
    if _DEFAULT is None:
        _DEFAULT = lazy_registry()
    return _DEFAULT

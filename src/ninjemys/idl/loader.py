"""From type names to message classes: find, parse, generate, compile once, cache.

``get_message_class("std_msgs/String")`` finds the definition (:mod:`ninjemys.idl.search`), parses it
and its dependencies, computes md5 and full text, generates the class source
(:mod:`ninjemys.idl.codegen`) and compiles it, once per process; later calls are a dict lookup.
Types that are only known from a publisher's or a bag's ``message_definition`` are built by
:func:`message_class_from_definition`.

User packages (how ``from my_pkg.msg import MyMsg`` works): there is no generate step. A package on
``ROS_PACKAGE_PATH`` (or under a sourced workspace's ``CMAKE_PREFIX_PATH``) is importable as soon as
its ``.msg`` files exist: the lazy module ``my_pkg.msg`` turns attribute access into
``get_message_class("my_pkg/MyMsg")``. That module comes either from the two-line stub
``catkin_make`` writes into ``devel/lib/python3/dist-packages/my_pkg/msg/__init__.py`` or, without
any build, from the import hook (:func:`install_import_hook`, installed by ``import rospy``).
"""

from __future__ import annotations

import importlib.machinery
import struct
import sys
import threading
from collections.abc import Callable
from types import ModuleType

from ninjemys.errors import DefinitionError, TypeNotFoundError
from ninjemys.idl import search
from ninjemys.idl.arrays import NumericArray
from ninjemys.idl.codecache import compile_cached
from ninjemys.idl.codegen import class_ref, generate_class_source
from ninjemys.idl.fulltext import all_dependencies, compute_full_text, split_full_text
from ninjemys.idl.hook import LazyInterfaceFinder, interface_package
from ninjemys.idl.md5 import compute_md5, compute_srv_md5
from ninjemys.idl.message import (
    DESER_ERRORS,
    SER_ERRORS,
    Message,
    ServiceClass,
    as_view,
    bad_args,
    deser_failed,
    encode_string,
    fixed_u8,
    pack_len,
    pack_numeric,
    short_buffer,
    u8_buffer,
)
from ninjemys.idl.parser import (
    ACTION_SUFFIXES,
    parse_action,
    parse_file,
    parse_message,
    read_definition,
    split_type_name,
)
from ninjemys.idl.spec import MsgSpec, SrvSpec
from ninjemys.rostime import Duration, Time

TYPE_CHECKING = False  # importing typing costs ~7 ms of every node's start-up; checkers set it
if TYPE_CHECKING:
    from typing import Any

_lock = threading.RLock()
_msg_specs: dict[str, MsgSpec] = {}
_srv_specs: dict[str, SrvSpec] = {}
_md5s: dict[str, str] = {}
_classes: dict[str, type[Message]] = {}
_srv_classes: dict[str, type[ServiceClass]] = {}
_from_definition: dict[tuple[str, str], type[Message]] = {}

_RUNTIME: dict[str, Any] = {
    "_Message": Message,
    "_Time": Time,
    "_Duration": Duration,
    "_NumArr": NumericArray,
    "_struct": struct,
    "_new": object.__new__,
    "_short": short_buffer,
    "_u8": u8_buffer,
    "_fixed_u8": fixed_u8,
    "_pack_num": pack_numeric,
    "_enc": encode_string,
    "_bad_args": bad_args,
    "_view": as_view,
    "_deser_failed": deser_failed,
    "_DESER_ERRORS": DESER_ERRORS,
    "_SER_ERRORS": SER_ERRORS,
    "_pack_len": pack_len,
}


def normalize_type_name(type_name: str) -> str:
    """Accept ``pkg/Type`` and ``pkg/msg/Type`` (ROS 2 / rosbags spelling); ``Header`` is std_msgs'."""
    if type_name == "Header":
        return "std_msgs/Header"
    parts = type_name.split("/")
    if len(parts) == 3 and parts[1] in ("msg", "srv", "action"):
        return f"{parts[0]}/{parts[2]}"
    return type_name


# --- specs --------------------------------------------------------------------------------------
def get_message_spec(type_name: str) -> MsgSpec:
    """The parsed spec of a message type (also action-generated and service request/response types)."""
    type_name = normalize_type_name(type_name)
    spec = _msg_specs.get(type_name)
    if spec is not None:
        return spec
    with _lock:
        spec = _msg_specs.get(type_name)
        if spec is None:
            spec = _load_message_spec(type_name)
            _msg_specs[type_name] = spec
    return spec


def _load_message_spec(type_name: str) -> MsgSpec:
    try:
        package, short = split_type_name(type_name)
    except DefinitionError:
        raise TypeNotFoundError(
            f"invalid message type name {type_name!r} (expected 'package/Type')"
        ) from None
    pkg = search.find_package(package)
    path = pkg.definitions("msg").get(short)
    if path is not None:
        spec = parse_file(path, package)
        assert isinstance(spec, MsgSpec)
        return spec
    actions = pkg.definitions("action")
    for suffix in sorted(ACTION_SUFFIXES, key=len, reverse=True):
        stem = short[: -len(suffix)]
        if short.endswith(suffix) and stem in actions:
            action = parse_action(read_definition(actions[stem]), f"{package}/{stem}", actions[stem])
            for generated in action.generated:
                _msg_specs.setdefault(generated.full_name, generated)
            return _msg_specs[type_name]
    for suffix in ("Request", "Response"):
        stem = short[: -len(suffix)]
        if short.endswith(suffix) and stem in pkg.definitions("srv"):
            srv = get_service_spec(f"{package}/{stem}")
            return srv.request if suffix == "Request" else srv.response
    raise TypeNotFoundError(
        f"message type {type_name} not found: package {package} at {pkg.path} has no msg/{short}.msg "
        f"(and no action or service generating it)"
    )


def get_service_spec(type_name: str) -> SrvSpec:
    type_name = normalize_type_name(type_name)
    spec = _srv_specs.get(type_name)
    if spec is not None:
        return spec
    with _lock:
        spec = _srv_specs.get(type_name)
        if spec is None:
            try:
                package, short = split_type_name(type_name)
            except DefinitionError:
                raise TypeNotFoundError(
                    f"invalid service type name {type_name!r} (expected 'package/Type')"
                ) from None
            parsed = parse_file(search.find_definition(package, short, "srv"), package)
            assert isinstance(parsed, SrvSpec)
            spec = _srv_specs[type_name] = parsed
    return spec


def get_message_md5(type_name: str) -> str:
    spec = get_message_spec(type_name)
    with _lock:
        return compute_md5(spec, get_message_spec, _md5s)


def get_full_text(type_name: str) -> str:
    return compute_full_text(get_message_spec(type_name), get_message_spec)


# --- classes ------------------------------------------------------------------------------------
def _build_class(
    spec: MsgSpec,
    lookup: Callable[[str], MsgSpec],
    class_of: Callable[[str], type[Message]],
    md5_cache: dict[str, str],
    module: str,
) -> type[Message]:
    deps = all_dependencies(spec, lookup)
    namespace = dict(_RUNTIME)
    for dep in deps:
        namespace[class_ref(dep)] = class_of(dep)
    md5sum = compute_md5(spec, lookup, md5_cache)
    full_text = compute_full_text(spec, lookup)
    source = generate_class_source(spec, lookup, md5sum, full_text)
    exec(compile_cached(source, f"<ninjemys generated {spec.full_name}>"), namespace)  # noqa: S102
    cls = namespace[spec.short_name]
    cls._fields = tuple((f.name, f.type) for f in spec.fields)
    cls._spec_lookup = (spec, lookup)  # what framedecode needs to generate the fused receive loop
    cls.__module__ = module
    cls._source = source
    return cls


def get_message_class(type_name: str) -> type[Message]:
    """The generated class of a message type (raises TypeNotFoundError naming what was searched)."""
    cls = _classes.get(type_name)
    if cls is not None:
        return cls
    name = normalize_type_name(type_name)
    with _lock:
        cls = _classes.get(name)
        if cls is None:
            spec = get_message_spec(name)
            kind = (
                "srv"
                if name.endswith(("Request", "Response")) and spec.path and spec.path.endswith(".srv")
                else "msg"
            )
            cls = _build_class(spec, get_message_spec, get_message_class, _md5s, f"{spec.package}.{kind}")
            _classes[name] = cls
        _classes[type_name] = cls
    return cls


def get_service_class(type_name: str) -> type[ServiceClass]:
    """The service class (``_type``, ``_md5sum``, ``_request_class``, ``_response_class``)."""
    cls = _srv_classes.get(type_name)
    if cls is not None:
        return cls
    name = normalize_type_name(type_name)
    with _lock:
        cls = _srv_classes.get(name)
        if cls is None:
            spec = get_service_spec(name)
            _msg_specs.setdefault(spec.request.full_name, spec.request)
            _msg_specs.setdefault(spec.response.full_name, spec.response)
            request = get_message_class(spec.request.full_name)
            response = get_message_class(spec.response.full_name)
            md5sum = compute_srv_md5(spec, get_message_spec, _md5s)
            cls = type(
                spec.short_name,
                (ServiceClass,),
                {
                    "__slots__": (),
                    "__module__": f"{spec.package}.srv",
                    "__doc__": f"The {name} service: a {request.__name__} and a {response.__name__}.",
                    "_type": name,
                    "_md5sum": md5sum,
                    "_request_class": request,
                    "_response_class": response,
                },
            )
            _srv_classes[name] = cls
        _srv_classes[type_name] = cls
    return cls


def message_class_from_definition(type_name: str, full_text: str, md5sum: str | None = None) -> type[Message]:
    """A class for ``type_name`` built from a ``message_definition`` text (connection header, bag).

    When the text's md5 equals the shipped/known type's, that class is returned (so messages from
    bags compare equal to the user's). Raises DefinitionError when ``md5sum`` is given (and not
    ``*``) and differs from the md5 the text yields.
    """
    type_name = normalize_type_name(type_name)
    key = (type_name, md5sum if md5sum and md5sum != "*" else full_text)
    cls = _from_definition.get(key)
    if cls is not None:
        return cls
    with _lock:
        specs: dict[str, MsgSpec] = {}
        for name, text in split_full_text(type_name, full_text).items():
            specs[name] = parse_message(text, name, f"<message_definition of {type_name}>")

        def lookup(name: str) -> MsgSpec:
            spec = specs.get(name)
            if spec is None:
                try:
                    spec = get_message_spec(name)
                except TypeNotFoundError:
                    raise TypeNotFoundError(
                        f"message definition of {type_name} uses {name} but does not contain it"
                    ) from None
            return spec

        local_md5: dict[str, str] = {}
        computed = compute_md5(specs[type_name], lookup, local_md5)
        if md5sum and md5sum != "*" and computed != md5sum:
            raise DefinitionError(
                f"{type_name}: message definition yields md5sum {computed}, but {md5sum} was announced"
            )
        try:
            known = get_message_class(type_name)
        except (TypeNotFoundError, DefinitionError):
            known = None
        if known is not None and known._md5sum == computed:
            cls = known
        else:
            local: dict[str, type[Message]] = {}

            def class_of(name: str) -> type[Message]:
                if name not in local:
                    local[name] = _build_class(
                        lookup(name), lookup, class_of, local_md5, f"{name.split('/')[0]}.msg"
                    )
                return local[name]

            cls = class_of(type_name)
        _from_definition[key] = cls
    return cls


# --- lazy package modules -----------------------------------------------------------------------
def _module_names(package: str, kind: str) -> list[str]:
    pkg = search.find_package(package)
    if kind == "srv":
        names = []
        for stem in pkg.definitions("srv"):
            names += [stem, f"{stem}Request", f"{stem}Response"]
        return sorted(names)
    names = list(pkg.definitions("msg"))
    for stem in pkg.definitions("action"):
        names += [f"{stem}{suffix}" for suffix in ACTION_SUFFIXES]
    return sorted(names)


def _resolve_attribute(package: str, kind: str, name: str) -> Any:
    if kind == "msg":
        return get_message_class(f"{package}/{name}")
    srvs = search.find_package(package).definitions("srv")
    if name in srvs:
        return get_service_class(f"{package}/{name}")
    for suffix, attr in (("Request", "_request_class"), ("Response", "_response_class")):
        if name.endswith(suffix) and name[: -len(suffix)] in srvs:
            return getattr(get_service_class(f"{package}/{name[: -len(suffix)]}"), attr)
    raise TypeNotFoundError(f"service type {package}/{name} not found in {search.find_package(package).path}")


def package_module_hooks(module_name: str) -> tuple[Callable[[str], Any], Callable[[], list[str]]]:
    """``(__getattr__, __dir__)`` for the lazy module ``<pkg>.msg`` or ``<pkg>.srv`` (PEP 562)."""
    package, _, kind = module_name.rpartition(".")
    if kind not in ("msg", "srv") or not package:
        raise ValueError(f"package_module_hooks expects '<pkg>.msg' or '<pkg>.srv', got {module_name!r}")

    def __getattr__(name: str) -> Any:
        if name == "__all__":
            return _module_names(package, kind)
        if name.startswith("__"):
            raise AttributeError(name)
        try:
            value = _resolve_attribute(package, kind, name)
        except TypeNotFoundError as exc:
            raise AttributeError(f"module {module_name!r} has no attribute {name!r}: {exc}") from None
        module = sys.modules.get(module_name)
        if module is not None:
            setattr(module, name, value)  # next access is a plain attribute lookup
        return value

    def __dir__() -> list[str]:
        try:
            return _module_names(package, kind)
        except TypeNotFoundError:
            return []

    return __getattr__, __dir__


class _InterfaceLoader:
    """Creates the lazy ``<pkg>``/``<pkg>.msg``/``<pkg>.srv`` modules (importlib's Loader protocol)."""

    def create_module(self, spec: importlib.machinery.ModuleSpec) -> ModuleType | None:
        return None

    def exec_module(self, module: ModuleType) -> None:
        name = module.__name__
        if name.endswith((".msg", ".srv")):
            module.__getattr__, module.__dir__ = package_module_hooks(name)  # type: ignore[method-assign]
        module.__path__ = []  # a package, so that `<pkg>.msg` can be imported below it


class InterfaceFinder:
    """Imports ``<pkg>``, ``<pkg>.msg`` and ``<pkg>.srv`` for interface packages nobody else provides.

    A plain class implementing importlib's MetaPathFinder protocol (importing ``importlib.abc`` would
    cost more start-up time than everything else here).
    """

    def find_spec(
        self, fullname: str, path: Any = None, target: Any = None
    ) -> importlib.machinery.ModuleSpec | None:
        return interface_module_spec(fullname) if interface_package(fullname) else None


def interface_module_spec(fullname: str) -> importlib.machinery.ModuleSpec:
    """The spec of the lazy module ``<pkg>``, ``<pkg>.msg`` or ``<pkg>.srv`` (an interface package)."""
    # _InterfaceLoader implements the Loader protocol without subclassing importlib.abc.Loader:
    # importing importlib.abc costs ~20 ms (it pulls importlib.resources) of every node's start-up
    loader = _InterfaceLoader()
    return importlib.machinery.ModuleSpec(fullname, loader, is_package=True)  # type: ignore[arg-type]


def install_import_hook() -> None:
    """Make ``from my_pkg.msg import MyMsg`` work for packages on ROS_PACKAGE_PATH (idempotent)."""
    if not any(isinstance(f, InterfaceFinder | LazyInterfaceFinder) for f in sys.meta_path):
        sys.meta_path.append(InterfaceFinder())

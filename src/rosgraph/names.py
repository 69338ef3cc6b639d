"""rosgraph.names: ROS 1's name functions, over ninjemys.names (the one implementation the master,
nodes, launch and tools share), with rosgraph's signatures and its ValueError on ``~`` globals."""

from __future__ import annotations

import os
import sys
from collections.abc import Mapping, Sequence

from ninjemys import names as _names

from .rosenv import ROS_NAMESPACE  # noqa: F401  (ROS 1 code reads it from here)

MSG_EXT = ".msg"
SRV_EXT = ".srv"
SEP = "/"
GLOBALNS = "/"
PRIV_NAME = "~"
REMAP = ":="
ANYTYPE = "*"

NAME_LEGAL_CHARS_P = _names._LEGAL
BASE_NAME_LEGAL_CHARS_P = _names._LEGAL_BASE
REMAP_PATTERN = _names._REMAP_ARG


def isstring(s: object) -> bool:
    """True for str (kept because ROS 1 code calls it to accept names)."""
    return isinstance(s, str)


def get_ros_namespace(env: Mapping[str, str] | None = None, argv: Sequence[str] | None = None) -> str:
    """The namespace from ``__ns:=`` or ROS_NAMESPACE, global and with a trailing ``/``."""
    return _names.get_ros_namespace(os.environ if env is None else env, sys.argv if argv is None else argv)


def make_caller_id(name: str) -> str:
    """``name`` in the process's namespace, as the global caller id with a trailing ``/``."""
    return make_global_ns(ns_join(get_ros_namespace(), name))


def make_global_ns(name: str) -> str:
    """``foo`` -> ``/foo/``; a ``~name`` has no global form (ValueError, as in ROS 1)."""
    if is_private(name):
        raise ValueError(f"cannot turn [{name}] into a global name")
    return _names.make_global_ns(name)


def is_global(name: str) -> bool:
    """True for a name starting with ``/`` (the empty name itself for an empty name, as in ROS 1)."""
    return name and _names.is_global(name)  # type: ignore[return-value]


def is_private(name: str) -> bool:
    """True for a name starting with ``~`` (the empty name itself for an empty name, as in ROS 1)."""
    return name and _names.is_private(name)  # type: ignore[return-value]


def namespace(name: str) -> str:
    """The namespace ``name`` lives in, with a trailing ``/`` (``/a/b`` -> ``/a/``); a relative name's
    namespace stays relative (``a/b`` -> ``a/``), unlike the node runtime's global-only form."""
    if name is None:
        raise ValueError("name")
    if not isinstance(name, str):
        raise TypeError("name")
    if not name:
        return SEP
    if name[-1] == SEP:
        name = name[:-1]
    return name[: name.rfind(SEP) + 1] or SEP


def ns_join(ns: str, name: str) -> str:
    """``name`` inside ``ns``; global and private names are returned unchanged."""
    return _names.ns_join(ns, name)


def load_mappings(argv: Sequence[str]) -> dict[str, str]:
    """The ``from:=to`` remappings of ``argv`` (``__name:=`` style special keys included), unresolved."""
    return _names.load_mappings(argv)


def is_legal_name(name: str) -> bool:
    """True for a name ROS 1 accepts (empty included)."""
    return _names.is_legal_name(name)


def is_legal_base_name(name: str) -> bool:
    """True for one segment: a letter, then letters, digits and ``_``."""
    return _names.is_legal_base_name(name)


def is_legal_remap(arg: str) -> bool:
    """True for a well formed ``from:=to`` argument."""
    return _names.is_remap_arg(arg)


def canonicalize_name(name: str) -> str:
    """Repeated and trailing ``/`` removed."""
    return _names.canonicalize_name(name)


def resolve_name(name: str, namespace_: str, remappings: Mapping[str, str] | None = None) -> str:
    """``name`` resolved for the node ``namespace_`` (``~x`` inside the node, ``x`` beside it),
    then looked up in ``remappings``."""
    return _names.resolve_name(name, namespace_, remappings)


def script_resolve_name(script_name: str, name: str) -> str:
    """``name`` resolved for a script (no remappings): ``~x`` under the script's caller id, relative
    names in ROS_NAMESPACE."""
    if not name:
        return get_ros_namespace()
    if is_global(name):
        return name
    if is_private(name):
        return ns_join(make_caller_id(script_name), name[1:])
    return get_ros_namespace() + name


def anonymous_name(id: str) -> str:  # noqa: A002  (ROS 1's parameter name)
    """``id`` followed by host, pid and a random number, legal as a ROS name."""
    return _names.anonymous_name(id)

"""ROS graph names: validation, resolution, remapping and command-line special keys.

A leaf module (stdlib only) because the master, the node runtime, launch and the tools all resolve
names and must agree exactly with ROS 1 (rosgraph.names):

* ``bar`` resolved for node ``/wg/node1`` is ``/wg/bar``; ``/bar`` stays; ``~bar`` is ``/wg/node1/bar``.
* Names are canonicalized: repeated and trailing ``/`` are removed.
* Remappings ``from:=to`` are resolved in the node's namespace before matching.
"""

from __future__ import annotations

import os
import re
import time
from collections.abc import Iterable, Mapping

from ninjemys.errors import NameError_

SEP = "/"
PRIV = "~"
REMAP = ":="
ANYTYPE = "*"

_LEGAL = re.compile(r"^[~/A-Za-z][\w/]*$")
_LEGAL_BASE = re.compile(r"^[A-Za-z][\w]*$")
_REMAP_ARG = re.compile(r"^([~/A-Za-z]|_|__)[\w/]*:=.*")


def is_legal_name(name: str) -> bool:
    """True for a name ROS 1 accepts: empty, or starting with a letter, ``~`` or ``/``, then [A-Za-z0-9_/]."""
    if name is None:
        return False
    if name == "":
        return True
    return bool(_LEGAL.match(name)) and "//" not in name


def is_legal_base_name(name: str) -> bool:
    """True for a single name segment (no slashes, no tilde)."""
    return bool(name) and bool(_LEGAL_BASE.match(name))


def is_global(name: str) -> bool:
    return name.startswith(SEP)


def is_private(name: str) -> bool:
    return name.startswith(PRIV)


def canonicalize_name(name: str) -> str:
    """Remove repeated and trailing separators (``//a//b/`` -> ``/a/b``); ``/`` stays ``/``."""
    if not name or name == SEP:
        return name
    leading = name.startswith(SEP)
    parts = [p for p in name.split(SEP) if p]
    joined = SEP.join(parts)
    return SEP + joined if leading else joined


def namespace(name: str) -> str:
    """The namespace of a global name, always ending with ``/`` (``/a/b`` -> ``/a/``, ``/a`` -> ``/``)."""
    if not name:
        return SEP
    if not name.startswith(SEP):
        name = SEP + name
    name = name.rstrip(SEP)
    head = name.rsplit(SEP, 1)[0]
    return head + SEP if head else SEP


def ns_join(ns: str, name: str) -> str:
    """Join a namespace and a name; global and private names are returned unchanged."""
    if is_private(name) or is_global(name):
        return name
    if ns == PRIV:
        return PRIV + name
    if not ns:
        return name
    return ns + name if ns.endswith(SEP) else ns + SEP + name


def make_global_ns(ns: str) -> str:
    """Turn ``foo`` / ``/foo`` / ``/foo/`` into ``/foo/`` (the form namespaces are stored in)."""
    if is_private(ns):
        raise NameError_(f"namespace [{ns}] must not be private")
    if not ns.startswith(SEP):
        ns = SEP + ns
    if not ns.endswith(SEP):
        ns += SEP
    return ns


def basename(name: str) -> str:
    return name.rstrip(SEP).rsplit(SEP, 1)[-1]


def resolve_name(name: str, caller_id: str, remappings: Mapping[str, str] | None = None) -> str:
    """Resolve ``name`` as node ``caller_id`` sees it (rosgraph.names.resolve_name semantics).

    Relative names resolve in the caller's namespace, private names (``~x``) under the caller's own
    name; the result is then looked up in ``remappings`` (keys and values already resolved).
    """
    if not name:
        return namespace(caller_id)
    name = canonicalize_name(name)
    if name.startswith(SEP):
        resolved = name
    elif name.startswith(PRIV):
        resolved = canonicalize_name(caller_id + SEP + name[1:])
    else:
        resolved = namespace(caller_id) + name
    if remappings and resolved in remappings:
        return remappings[resolved]
    return resolved


def is_remap_arg(arg: str) -> bool:
    """True for a command-line argument of the form ``from:=to`` (including ``__name:=`` and ``_p:=``)."""
    return bool(_REMAP_ARG.match(arg))


def load_mappings(argv: Iterable[str]) -> dict[str, str]:
    """Every ``from:=to`` argument, unresolved, as rosgraph.names.load_mappings returns them.

    Private parameter assignments (``_param:=v``) are excluded; special keys (``__name``) are kept.
    """
    mappings: dict[str, str] = {}
    for arg in argv:
        if REMAP not in arg or not is_remap_arg(arg):
            continue
        src, dst = arg.split(REMAP, 1)
        src, dst = src.strip(), dst.strip()
        if src and dst and not (src.startswith("_") and not src.startswith("__")):
            mappings[src] = dst
    return mappings


def private_param_args(argv: Iterable[str]) -> dict[str, str]:
    """``_param:=value`` arguments as {"param": "value"} (values still unparsed YAML text)."""
    params: dict[str, str] = {}
    for arg in argv:
        if REMAP not in arg or not arg.startswith("_") or arg.startswith("__"):
            continue
        src, dst = arg.split(REMAP, 1)
        if src[1:]:
            params[src[1:]] = dst
    return params


def strip_remap_args(argv: Iterable[str]) -> list[str]:
    """argv without any ``x:=y`` argument (rospy.myargv)."""
    return [a for a in argv if not (REMAP in a and is_remap_arg(a))]


def resolve_remappings(mappings: Mapping[str, str], caller_id: str) -> dict[str, str]:
    """Resolve both sides of the user remappings (not the ``__special`` keys) for ``caller_id``."""
    resolved: dict[str, str] = {}
    for src, dst in mappings.items():
        if src.startswith("__"):
            continue
        resolved[resolve_name(src, caller_id)] = resolve_name(dst, caller_id)
    return resolved


def anonymous_name(base: str) -> str:
    """``base_<hostname>_<pid>_<random>`` as rosgraph/roslaunch ``$(anon base)`` builds it."""
    import random  # imported here: every tool and node imports this module, few need anonymous names
    import socket

    host = re.sub(r"[.\-:]", "_", socket.gethostname())
    return f"{base}_{host}_{os.getpid()}_{random.randint(0, 2**63)}"


def rospy_anonymous_name(base: str) -> str:
    """``base_<pid>_<ms since epoch>``: the form rospy.init_node(anonymous=True) uses."""
    return f"{base}_{os.getpid()}_{int(time.time() * 1000)}"


def get_ros_namespace(env: Mapping[str, str] | None = None, argv: Iterable[str] | None = None) -> str:
    """The node namespace from ``__ns:=`` (wins) or ROS_NAMESPACE, as a global ``/ns/`` string."""
    env = os.environ if env is None else env
    ns = env.get("ROS_NAMESPACE", SEP)
    for arg in argv or ():
        if arg.startswith("__ns:="):
            ns = arg[len("__ns:=") :]
    return make_global_ns(ns)

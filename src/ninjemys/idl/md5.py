"""md5sums exactly as ROS 1 computes them (genmsg ``compute_md5_text`` / ``compute_md5``).

The md5 text of a message is: each constant as ``TYPE NAME=VALUE_TEXT``, then each field as
``TYPE NAME`` for builtins (array suffix kept, ``byte``/``char`` spelled as written) or
``MD5 NAME`` for nested messages (package and array suffix dropped, replaced by the nested type's md5,
recursively), joined by newlines and stripped. A service's md5 hashes the request's md5 text directly
followed by the response's.
"""

from __future__ import annotations

import hashlib
from collections.abc import Callable

from ninjemys.errors import DefinitionError
from ninjemys.idl.spec import MsgSpec, SrvSpec

#: resolves a ``pkg/Type`` to its spec (raises TypeNotFoundError when unknown)
Lookup = Callable[[str], MsgSpec]


def compute_md5_text(
    spec: MsgSpec, lookup: Lookup, cache: dict[str, str] | None = None, _active: tuple[str, ...] = ()
) -> str:
    """The text whose md5 is the type's md5sum."""
    lines = [f"{c.type} {c.name}={c.value_text}" for c in spec.constants]
    for f in spec.fields:
        if f.type.is_builtin:
            lines.append(f"{f.type} {f.name}")
        else:
            lines.append(f"{compute_md5(lookup(f.type.base), lookup, cache, _active)} {f.name}")
    return "\n".join(lines).strip()


def compute_md5(
    spec: MsgSpec, lookup: Lookup, cache: dict[str, str] | None = None, _active: tuple[str, ...] = ()
) -> str:
    """The md5sum of a message type; ``cache`` (full name -> md5) avoids recomputing shared subtypes.

    A type that contains itself (directly or through others) has no md5 and no wire form: DefinitionError.
    """
    if cache is not None:
        hit = cache.get(spec.full_name)
        if hit is not None:
            return hit
    if spec.full_name in _active:
        chain = " -> ".join((*_active, spec.full_name))
        raise DefinitionError(f"recursive message type: {chain}", spec.path)
    active = (*_active, spec.full_name)
    digest = hashlib.md5(compute_md5_text(spec, lookup, cache, active).encode()).hexdigest()
    if cache is not None:
        cache[spec.full_name] = digest
    return digest


def compute_srv_md5(spec: SrvSpec, lookup: Lookup, cache: dict[str, str] | None = None) -> str:
    """The md5sum of a service: md5 of request md5 text + response md5 text."""
    text = compute_md5_text(spec.request, lookup, cache) + compute_md5_text(spec.response, lookup, cache)
    return hashlib.md5(text.encode()).hexdigest()

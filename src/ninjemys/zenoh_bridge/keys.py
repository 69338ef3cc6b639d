"""Zenoh key expressions in zenoh-plugin-ros1's layout (pure: no Zenoh, no sockets).

Data: ``<hex(datatype)>/<md5>/<bridge_ns>/<topic without its leading slash>``, for messages (put),
service requests (query) and replies. The datatype is hex-encoded because ``/`` inside it would
split the key. Discovery beacons: ``ros1_discovery_info/<discovery_ns>/<pub|sub|srv|cl>/<hex
datatype>/<md5>/<bridge_ns>/<topic>``, an empty put each second while the resource lives here.
``bridge_ns`` is the per-robot prefix; ``*`` (the default) is the wildcard namespace that meets
every other one, as in the Rust bridge.
"""

from __future__ import annotations

from typing import NamedTuple

from ninjemys.errors import NinjemysError

DISCOVERY_ROOT = "ros1_discovery_info"
#: resource classes of the discovery keys (the Rust bridge's spelling)
PUB, SUB, SRV, CL = "pub", "sub", "srv", "cl"
CLASSES = (PUB, SUB, SRV, CL)


class KeyError_(NinjemysError, ValueError):
    """A key expression that is not in zenoh-plugin-ros1's layout."""


class Resource(NamedTuple):
    """A topic or service as the bridges name it: graph name, datatype and md5sum."""

    name: str
    datatype: str
    md5: str


def topic_key(name: str) -> str:
    """The topic part of a key: the graph name without its leading and trailing slashes."""
    return name.strip("/")


def data_key(res: Resource, bridge_ns: str) -> str:
    """Where ``res``'s messages (or service calls) travel."""
    return f"{res.datatype.encode().hex()}/{res.md5}/{bridge_ns}/{topic_key(res.name)}"


def discovery_key(res: Resource, kind: str, bridge_ns: str, discovery_ns: str = "*") -> str:
    """The beacon key announcing that ``res`` of ``kind`` (pub/sub/srv/cl) lives behind a bridge."""
    if kind not in CLASSES:
        raise KeyError_(f"unknown resource class {kind!r} (expected one of {', '.join(CLASSES)})")
    return f"{DISCOVERY_ROOT}/{discovery_ns}/{kind}/{data_key(res, bridge_ns)}"


def discovery_selector(bridge_ns: str, discovery_ns: str = "*") -> str:
    """What a bridge listens to: every class, type and md5 in its namespace (topics of >= 1 chunk)."""
    return f"{DISCOVERY_ROOT}/{discovery_ns}/*/*/*/{bridge_ns}/*/**"


def parse_discovery(key: str) -> tuple[str, Resource]:
    """``(kind, resource)`` of a beacon key; :class:`KeyError_` names what is wrong with it."""
    parts = key.split("/")
    if len(parts) < 7 or parts[0] != DISCOVERY_ROOT:
        raise KeyError_(f"discovery key {key!r}: expected {DISCOVERY_ROOT}/ns/class/type/md5/bridge_ns/topic")
    kind, hex_type, md5 = parts[2], parts[3], parts[4]
    if kind not in CLASSES:
        raise KeyError_(f"discovery key {key!r}: unknown resource class {kind!r}")
    try:
        datatype = bytes.fromhex(hex_type).decode()
    except ValueError:
        raise KeyError_(f"discovery key {key!r}: datatype {hex_type!r} is not hex-encoded UTF-8") from None
    return kind, Resource("/" + "/".join(parts[6:]), datatype, md5)

"""rospy.names: graph-name helpers as rospy exposes them (thin re-exports of ninjemys.names)."""

from __future__ import annotations

from ninjemys.names import (
    PRIV as PRIV_NAME,
)
from ninjemys.names import (
    SEP,
    canonicalize_name,
    is_global,
    is_legal_name,
    is_private,
    ns_join,
)
from rospy.client import get_caller_id, get_name, get_namespace, resolve_name
from rospy.core import _process

__all__ = [
    "SEP",
    "PRIV_NAME",
    "canonicalize_name",
    "get_caller_id",
    "get_mappings",
    "get_name",
    "get_namespace",
    "get_resolved_mappings",
    "is_global",
    "is_legal_name",
    "is_private",
    "ns_join",
    "resolve_name",
]


def get_resolved_mappings() -> dict[str, str]:
    """The node's remappings, both sides resolved (empty before init_node)."""
    node = _process.node
    return dict(node.remappings) if node is not None else {}


def get_mappings() -> dict[str, str]:
    """The command-line ``from:=to`` remappings as typed, special keys (``__name`` ...) included."""
    import sys

    from ninjemys.names import load_mappings

    return load_mappings(sys.argv)

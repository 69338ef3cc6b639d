"""The parts of a node reach it only through NodeContext, and Node provides all of it."""

from __future__ import annotations

import ast
import inspect
from pathlib import Path

from ninjemys.node import Node
from ninjemys.node.context import NodeContext

PARTS = ["topics", "subscriber", "services", "registration", "slave"]
NODE_DIR = Path(__file__).resolve().parents[2] / "src" / "ninjemys" / "node"


def _protocol_members() -> set[str]:
    names = set(NodeContext.__annotations__)
    names |= {
        n
        for n, v in vars(NodeContext).items()
        if not n.startswith("_") and (callable(v) or isinstance(v, property))
    }
    return names


def test_a_live_node_has_every_member_of_the_protocol(make_node) -> None:
    node = make_node("context_node")
    members = _protocol_members()
    assert {"release_publisher", "publisher_update", "runtime", "master", "is_shutdown"} <= members
    missing = [name for name in sorted(members) if not hasattr(node, name)]
    assert not missing, f"Node lacks NodeContext members: {missing}"
    for name in members:
        proto = getattr(NodeContext, name, None)
        if callable(proto):
            wanted = list(inspect.signature(proto).parameters)[1:]
            assert list(inspect.signature(getattr(Node, name)).parameters)[1:] == wanted, name


def test_parts_use_only_the_protocol() -> None:
    """Every ``<x>.node.<attr>`` / ``self._node.<attr>`` a part uses is a NodeContext member."""
    members = _protocol_members()
    used: list[str] = []
    for part in PARTS:
        path = NODE_DIR / f"{part}.py"
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if not isinstance(node, ast.Attribute):
                continue
            owner = node.value
            if isinstance(owner, ast.Attribute) and owner.attr in ("node", "_node"):
                if node.attr not in members:
                    used.append(f"{path.name}:{node.lineno}: node.{node.attr}")
            elif isinstance(owner, ast.Name) and owner.id == "node" and node.attr not in members:
                used.append(f"{path.name}:{node.lineno}: node.{node.attr}")
    assert not used, "parts reaching past NodeContext:\n" + "\n".join(used)

"""The launch plan is plain data: it imports nothing of the runner or the master link (the circle
plan -> master_link -> runner -> plan is gone); whether a machine is this host is a net question."""

from __future__ import annotations

import ast
from pathlib import Path

import ninjemys.launch.plan as plan
from ninjemys.net.addresses import is_local_address


def test_plan_imports_no_launch_runtime() -> None:
    tree = ast.parse(Path(plan.__file__).read_text(encoding="utf-8"))
    imported = set()
    for node in ast.walk(tree):  # every form: top level, inside functions, TYPE_CHECKING
        if isinstance(node, ast.ImportFrom) and node.module:
            imported.add(node.module)
        elif isinstance(node, ast.Import):
            imported.update(alias.name for alias in node.names)
    assert not {m for m in imported if m.startswith("ninjemys.launch")}, imported
    assert "ninjemys.net.addresses" in imported


def test_is_local_address_knows_loopback_and_strangers() -> None:
    assert is_local_address("localhost") and is_local_address("127.0.0.1") and is_local_address("")
    assert not is_local_address("no-such-host.invalid")

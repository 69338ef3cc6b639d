"""Fixtures for node runtime tests: a master on a free port, nodes that are always shut down."""

from __future__ import annotations

import sys
from collections.abc import Callable, Iterator
from pathlib import Path

import pytest

from ninjemys import testing
from ninjemys.node import Node
from ninjemys.testing import wait_until  # noqa: E402

sys.path.insert(0, str(Path(__file__).parent))

from node_harness import MasterProcess  # noqa: E402

__all__ = ["MasterProcess", "wait_until"]


@pytest.fixture
def master() -> Iterator[MasterProcess]:
    m = MasterProcess(testing.free_port())
    m.start()
    try:
        yield m
    finally:
        m.kill()


@pytest.fixture
def make_node(master: MasterProcess) -> Iterator[Callable[..., Node]]:
    nodes: list[Node] = []

    def make(name: str, **kwargs: object) -> Node:
        node = Node(name, master_uri=master.uri, **kwargs)  # type: ignore[arg-type]
        nodes.append(node)
        return node

    try:
        yield make
    finally:
        for node in nodes:
            node.shutdown("test over")

"""Fixtures for node runtime tests: a master on a free port, nodes that are always shut down."""

from __future__ import annotations

import subprocess
import sys
import time
from collections.abc import Callable, Iterator
from pathlib import Path

import pytest

from ninjemys import testing
from ninjemys.master.client import MasterClient
from ninjemys.node import Node

sys.path.insert(0, str(Path(__file__).parent))


def wait_until(predicate: Callable[[], object], timeout: float = 5.0, step: float = 0.01) -> bool:
    """Poll ``predicate`` until it is truthy (test helper only)."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if predicate():
            return True
        time.sleep(step)
    return bool(predicate())


class MasterProcess:
    """A master in a child process on a fixed port, restartable (for master-restart tests)."""

    def __init__(self, port: int, kind: str = "ninjemys") -> None:
        self.port = port
        self.kind = kind
        self.uri = f"http://localhost:{port}/"
        self.proc: subprocess.Popen[bytes] | None = None

    def start(self) -> None:
        if self.kind == "ros1":
            cmd = ["/usr/bin/rosmaster", "--core", "-p", str(self.port), "-w", "3"]
            env = testing.ros1_env(self.uri)
        else:
            cmd = [testing.ninjemys_bin("roscore"), "-p", str(self.port)]
            env = None
        self.proc = subprocess.Popen(cmd, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        client = MasterClient(self.uri, "/probe", timeout=1.0)
        try:
            if not wait_until(client.is_online, timeout=15.0, step=0.05):
                raise RuntimeError(f"master on port {self.port} did not come up")
        finally:
            client.close()

    def kill(self) -> None:
        if self.proc is not None:
            self.proc.kill()
            self.proc.wait()
            self.proc = None


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

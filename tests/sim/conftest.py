"""Fixtures: our roscore, a turtlesim_node process, and an in-test client node."""

from __future__ import annotations

import os
from collections.abc import Callable, Iterator
from pathlib import Path

import pytest

from ninjemys.testing import NodeProcess, free_port, ninjemys_bin, run_master


@pytest.fixture
def master() -> Iterator[str]:
    with run_master() as uri:
        yield uri


class TurtlesimProcess(NodeProcess):
    """A running turtlesim_node (stderr merged into stdout); ``log()`` is everything it printed so far."""

    web_port: int | None = None

    def log(self) -> str:
        return self.text()

    def wait_for_log(self, text: str, timeout: float = 20.0) -> str:
        """The output so far, once it contains ``text`` (fails the test if it never does)."""
        self.wait_for(lambda _line: text in self.text(), timeout)
        return self.text()


def start_turtlesim(master_uri: str, tmp_path: Path, *args: str, web: bool = False) -> TurtlesimProcess:
    env = dict(os.environ, ROS_MASTER_URI=master_uri, PYTHONUNBUFFERED="1")
    port = free_port() if web else None
    cmd = [ninjemys_bin("turtlesim_node"), *args]
    cmd += ["--port", str(port)] if web else ["--headless"]
    sim = TurtlesimProcess(cmd, env=env, cwd=tmp_path, merge_stderr=True)
    sim.web_port = port
    try:
        sim.wait_for_log("Spawning turtle [turtle1]")
        if web:
            sim.wait_for_log("turtlesim view:")
    except BaseException:
        sim.kill()
        raise
    return sim


@pytest.fixture
def turtlesim(master: str, tmp_path: Path) -> Iterator[Callable[..., TurtlesimProcess]]:
    started: list[TurtlesimProcess] = []

    def start(*args: str, web: bool = False) -> TurtlesimProcess:
        sim = start_turtlesim(master, tmp_path, *args, web=web)
        started.append(sim)
        return sim

    try:
        yield start
    finally:
        for sim in started:
            sim.stop(grace=5.0)


@pytest.fixture
def client(master: str):  # type: ignore[no-untyped-def]
    from ninjemys.node import Node

    node = Node("turtle_test_client", anonymous=True, master_uri=master)
    try:
        yield node
    finally:
        node.shutdown("test over")

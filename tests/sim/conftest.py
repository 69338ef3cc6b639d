"""Fixtures: our roscore, a turtlesim_node process, and an in-test client node."""

from __future__ import annotations

import os
import subprocess
import time
from collections.abc import Callable, Iterator
from pathlib import Path

import pytest

from ninjemys.testing import free_port, ninjemys_bin, run_master


@pytest.fixture
def master() -> Iterator[str]:
    with run_master() as uri:
        yield uri


class TurtlesimProcess:
    """A running turtlesim_node; ``log()`` is everything it printed so far."""

    def __init__(self, proc: subprocess.Popen, log_path: Path, web_port: int | None) -> None:
        self.proc = proc
        self.log_path = log_path
        self.web_port = web_port

    def log(self) -> str:
        return self.log_path.read_text(errors="replace")

    def wait_for_log(self, text: str, timeout: float = 20.0) -> str:
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            out = self.log()
            if text in out:
                return out
            if self.proc.poll() is not None:
                raise AssertionError(f"turtlesim_node exited ({self.proc.returncode}):\n{out}")
            time.sleep(0.05)
        raise AssertionError(f"turtlesim_node never printed {text!r}:\n{self.log()}")


def start_turtlesim(master_uri: str, tmp_path: Path, *args: str, web: bool = False) -> TurtlesimProcess:
    env = dict(os.environ, ROS_MASTER_URI=master_uri, PYTHONUNBUFFERED="1")
    log_path = tmp_path / f"turtlesim-{free_port()}.log"
    port = free_port() if web else None
    cmd = [ninjemys_bin("turtlesim_node"), *args]
    cmd += ["--port", str(port)] if web else ["--headless"]
    with open(log_path, "wb") as out:
        proc = subprocess.Popen(cmd, env=env, stdout=out, stderr=subprocess.STDOUT, stdin=subprocess.DEVNULL)
    sim = TurtlesimProcess(proc, log_path, port)
    try:
        sim.wait_for_log("Spawning turtle [turtle1]")
        if web:
            sim.wait_for_log("turtlesim view:")
    except BaseException:
        proc.kill()
        proc.wait()
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
            sim.proc.terminate()
            try:
                sim.proc.wait(5)
            except subprocess.TimeoutExpired:
                sim.proc.kill()
                sim.proc.wait()


@pytest.fixture
def client(master: str):  # type: ignore[no-untyped-def]
    from ninjemys.node import Node

    node = Node("turtle_test_client", anonymous=True, master_uri=master)
    try:
        yield node
    finally:
        node.shutdown("test over")

"""Fixtures for rospy facade tests: a master per test module and node processes that always get killed."""

from __future__ import annotations

import os
import re
import signal
import subprocess
import sys
import threading
import time
from collections.abc import Iterator
from pathlib import Path

import pytest

from ninjemys.testing import run_master


class NodeProc:
    """A Python node running as a child process, with its stdout/stderr collected line by line."""

    def __init__(self, cmd: list[str], env: dict[str, str], cwd: Path) -> None:
        self.cmd = cmd
        self.proc = subprocess.Popen(
            cmd, env=env, cwd=cwd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, stdin=subprocess.DEVNULL
        )
        self.out: list[str] = []
        self.err: list[str] = []
        self._cond = threading.Condition()
        self._readers = [
            threading.Thread(target=self._read, args=(self.proc.stdout, self.out), daemon=True),
            threading.Thread(target=self._read, args=(self.proc.stderr, self.err), daemon=True),
        ]
        for r in self._readers:
            r.start()

    def _read(self, stream, sink: list[str]) -> None:
        for raw in iter(stream.readline, b""):
            with self._cond:
                sink.append(raw.decode("utf-8", "replace").rstrip("\n"))
                self._cond.notify_all()
        stream.close()
        with self._cond:
            self._cond.notify_all()

    def wait_for(self, pattern: str, timeout: float = 15.0, stream: str = "out") -> re.Match[str]:
        """The first line of stdout (or stderr) matching ``pattern``; fails the test after ``timeout``."""
        regex = re.compile(pattern)
        sink = self.out if stream == "out" else self.err
        deadline = time.monotonic() + timeout
        with self._cond:
            while True:
                for line in sink:
                    m = regex.search(line)
                    if m:
                        return m
                left = deadline - time.monotonic()
                if left <= 0 or (
                    self.proc.poll() is not None and not any(r.is_alive() for r in self._readers)
                ):
                    raise AssertionError(
                        f"{self.cmd}: no line matching {pattern!r} on std{stream} within {timeout} s\n"
                        f"stdout: {self.out[-20:]}\nstderr: {self.err[-20:]}"
                    )
                self._cond.wait(min(left, 0.5))

    def interrupt(self) -> None:
        self.proc.send_signal(signal.SIGINT)

    def wait(self, timeout: float = 10.0) -> int:
        code = self.proc.wait(timeout)
        for r in self._readers:
            r.join(2.0)
        return code

    def kill(self) -> None:
        if self.proc.poll() is None:
            self.proc.kill()
        self.proc.wait()
        for r in self._readers:
            r.join(2.0)


@pytest.fixture(scope="module")
def master(tmp_path_factory: pytest.TempPathFactory) -> Iterator[str]:
    home = tmp_path_factory.mktemp("master_home")
    env = dict(os.environ, ROS_HOME=str(home), ROS_HOSTNAME="localhost")
    env.pop("ROS_LOG_DIR", None)
    with run_master(env=env) as uri:
        yield uri


@pytest.fixture
def node_env(master: str, tmp_path: Path) -> dict[str, str]:
    env = dict(os.environ)
    for key in ("ROS_NAMESPACE", "ROS_LOG_DIR", "ROSCONSOLE_FORMAT", "ROS_IP"):
        env.pop(key, None)
    env.update(
        ROS_MASTER_URI=master,
        ROS_HOME=str(tmp_path / "ros_home"),
        ROS_HOSTNAME="localhost",
        PYTHONUNBUFFERED="1",
    )
    return env


@pytest.fixture
def run_node(node_env: dict[str, str], tmp_path: Path) -> Iterator:
    """``run_node(code_or_path, *args, env=None)`` starts a node process; all are killed at teardown."""
    started: list[NodeProc] = []
    counter = [0]

    def start(script: str | Path, *args: str, env: dict[str, str] | None = None) -> NodeProc:
        if isinstance(script, Path):
            path = script
        else:
            counter[0] += 1
            path = tmp_path / f"node_{counter[0]}.py"
            path.write_text(script)
        proc = NodeProc([sys.executable, str(path), *args], env or node_env, tmp_path)
        started.append(proc)
        return proc

    try:
        yield start
    finally:
        for proc in started:
            proc.kill()

"""Fixtures and helpers for launch tests: corpus packages on ROS_PACKAGE_PATH, running roslaunch."""

from __future__ import annotations

import os
import queue
import re
import signal
import subprocess
import threading
import time
from collections.abc import Callable, Iterator
from pathlib import Path

import pytest

from ninjemys.testing import ninjemys_bin

DATA = Path(__file__).parent / "data"
PKGS = DATA / "pkgs"


@pytest.fixture
def corpus_env(monkeypatch: pytest.MonkeyPatch) -> dict[str, str]:
    """The environment both roslaunch implementations see for the corpus."""
    env = {
        "ROS_PACKAGE_PATH": str(PKGS),
        "NJ_CORPUS_USER": "tester",
        "ROS_MASTER_URI": "http://localhost:11311",
    }
    for key, value in env.items():
        monkeypatch.setenv(key, value)
    monkeypatch.delenv("NJ_CORPUS_HOME", raising=False)
    monkeypatch.delenv("CMAKE_PREFIX_PATH", raising=False)
    return env


@pytest.fixture
def env(tmp_path: Path, port: int) -> dict[str, str]:
    e = dict(os.environ)
    e.update(
        ROS_MASTER_URI=f"http://localhost:{port}",
        ROS_PACKAGE_PATH=str(PKGS),
        ROS_HOME=str(tmp_path / "ros_home"),
        PYTHONUNBUFFERED="1",
    )
    e.pop("CMAKE_PREFIX_PATH", None)
    return e


class Launch:
    """A running roslaunch whose stdout lines are collected by a reader thread."""

    def __init__(self, args: list[str], env: dict[str, str]) -> None:
        self.proc = subprocess.Popen(
            [ninjemys_bin("roslaunch"), *args],
            env=env,
            stdin=subprocess.DEVNULL,
            stdout=subprocess.PIPE,
            stderr=subprocess.STDOUT,
            text=True,
        )
        self.lines: list[str] = []
        self._queue: queue.Queue[str | None] = queue.Queue()
        threading.Thread(target=self._read, daemon=True).start()

    def _read(self) -> None:
        assert self.proc.stdout is not None
        for line in self.proc.stdout:
            self._queue.put(line)
        self._queue.put(None)

    def wait_for(self, predicate: Callable[[list[str]], bool], timeout: float = 60.0) -> bool:
        deadline = time.monotonic() + timeout
        while not predicate(self.lines):
            remaining = deadline - time.monotonic()
            if remaining <= 0:
                return False
            try:
                line = self._queue.get(timeout=remaining)
            except queue.Empty:
                return False
            if line is None:
                return predicate(self.lines)
            self.lines.append(line)
        return True

    def finish(self, timeout: float = 30.0) -> int:
        code = self.proc.wait(timeout)
        self.wait_for(lambda _: False, timeout=2.0)
        return code

    def pids(self) -> list[int]:
        return [int(m) for line in self.lines for m in re.findall(r"started with pid \[(\d+)\]", line)]

    def kill(self) -> None:
        if self.proc.poll() is None:
            self.proc.kill()
        self.proc.wait()


@pytest.fixture
def launches() -> Iterator[list[Launch]]:
    started: list[Launch] = []
    try:
        yield started
    finally:
        for launch in started:
            pids = launch.pids()
            launch.kill()
            for pid in pids:
                try:
                    os.killpg(pid, signal.SIGKILL)
                except (ProcessLookupError, PermissionError):
                    pass


def alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    try:
        with open(f"/proc/{pid}/stat") as f:
            return f.read().split()[2] != "Z"
    except OSError:
        return False


def write_launch(tmp_path: Path, body: str, name: str = "test.launch") -> Path:
    path = tmp_path / name
    path.write_text(f"<launch>\n{body}\n</launch>\n")
    return path


def run_cli(args: list[str], env: dict[str, str]) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [ninjemys_bin("roslaunch"), *args], env=env, capture_output=True, text=True, timeout=60, check=False
    )

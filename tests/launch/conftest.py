"""Fixtures and helpers for launch tests: corpus packages on ROS_PACKAGE_PATH, running roslaunch."""

from __future__ import annotations

import os
import re
import signal
import subprocess
from collections.abc import Callable, Iterator
from pathlib import Path

import pytest

from ninjemys.testing import NodeProcess, WaitTimeout, ninjemys_bin

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
    """A running roslaunch (a :class:`ninjemys.testing.NodeProcess`, stderr merged into stdout), waited on
    through predicates over all its output lines so far."""

    def __init__(self, args: list[str], env: dict[str, str]) -> None:
        self.child = NodeProcess([ninjemys_bin("roslaunch"), *args], env=env, merge_stderr=True)
        self.proc = self.child.proc

    @property
    def lines(self) -> list[str]:
        """Every line printed so far, each with its newline (as the launch printed it)."""
        return [line + "\n" for line in list(self.child.out)]

    def wait_for(self, predicate: Callable[[list[str]], bool], timeout: float = 60.0) -> bool:
        """True once ``predicate(lines)`` holds; False after ``timeout`` or once roslaunch has ended
        without it."""
        try:
            self.child.wait_for(lambda _line: predicate(self.lines), timeout)
            return True
        except WaitTimeout:
            return predicate(self.lines)

    def finish(self, timeout: float = 30.0) -> int:
        return self.child.wait(timeout)

    def pids(self) -> list[int]:
        return [int(m) for line in self.lines for m in re.findall(r"started with pid \[(\d+)\]", line)]

    def kill(self) -> None:
        self.child.kill()


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

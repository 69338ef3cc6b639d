"""Fixtures for rospy facade tests: a master per test module and node processes that always get killed."""

from __future__ import annotations

import os
import sys
from collections.abc import Iterator
from pathlib import Path

import pytest

from ninjemys.testing import NodeProcess, run_master


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
    started: list[NodeProcess] = []
    counter = [0]

    def start(script: str | Path, *args: str, env: dict[str, str] | None = None) -> NodeProcess:
        if isinstance(script, Path):
            path = script
        else:
            counter[0] += 1
            path = tmp_path / f"node_{counter[0]}.py"
            path.write_text(script)
        proc = NodeProcess([sys.executable, str(path), *args], env or node_env, tmp_path)
        started.append(proc)
        return proc

    try:
        yield start
    finally:
        for proc in started:
            proc.kill()

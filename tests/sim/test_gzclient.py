"""``gzclient`` says what it is and what it can do (issue 23 leftovers): it is not Gazebo's 3D
client but opens the simulator's browser view; a headless gzserver has no view, which gzclient says
before exiting 1; an address left by a server that has gone is not opened."""

from __future__ import annotations

import os
from collections.abc import Iterator
from pathlib import Path

import pytest
from gazebo_helpers import Launched

from ninjemys.node import Node
from ninjemys.testing import ninjemys_bin, run_master


@pytest.fixture
def master() -> Iterator[str]:
    with run_master() as uri:
        yield uri


def env_for(master: str) -> dict[str, str]:
    env = dict(os.environ, ROS_MASTER_URI=master, PYTHONUNBUFFERED="1")
    for key in ("DISPLAY", "WAYLAND_DISPLAY"):
        env.pop(key, None)
    return env


def test_gzclient_facing_a_headless_server_says_so_and_exits_1(master: str, tmp_path: Path) -> None:
    server = Launched([ninjemys_bin("gzserver"), "--headless"], env_for(master), tmp_path / "server.log")
    try:
        server.wait_for("PuzzleBot simulator:")
        client = Launched([ninjemys_bin("gzclient")], env_for(master), tmp_path / "client.log")
        try:
            assert client.proc.wait(30) == 1
            out = client.log()
            assert "not Gazebo's 3D client" in out
            assert "gzserver runs headless: there is no view to attach to" in out
            assert "simulator view http" not in out
        finally:
            client.stop()
    finally:
        server.stop()


def test_gzclient_does_not_open_an_address_that_does_not_answer(master: str, tmp_path: Path) -> None:
    node = Node("stale_server", anonymous=True, master_uri=master)
    try:
        node.set_param("/gazebo/gui_url", "http://127.0.0.1:9/puzzlebot")  # the discard port: nobody
        client = Launched([ninjemys_bin("gzclient")], env_for(master), tmp_path / "client.log")
        try:
            out = client.wait_for("does not answer")
            assert "http://127.0.0.1:9/puzzlebot" in out and "simulator view http" not in out
            assert client.proc.poll() is None  # still waiting for a live server
        finally:
            client.stop()
    finally:
        node.shutdown("test over")

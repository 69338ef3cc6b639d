"""``rosrun tf2_ros buffer_server`` and ``tf2_ros.BufferClient``: ours answer as tf2_ros's do, and
Debian's BufferClient gets the same answers from our server."""

from __future__ import annotations

import json
import os
import subprocess
import sys
import time
from collections.abc import Iterator
from pathlib import Path

import pytest

from ninjemys import testing

PEER = str(Path(__file__).with_name("parity_buffer_client_peer.py"))
ROSRUN = str(Path(sys.executable).with_name("rosrun"))


@pytest.fixture
def server() -> Iterator[str]:
    with testing.run_master() as master:
        env = {**os.environ, "ROS_MASTER_URI": master, "ROS_HOSTNAME": "localhost"}
        proc = subprocess.Popen(
            [ROSRUN, "tf2_ros", "buffer_server"], env=env, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE
        )
        try:
            time.sleep(1.0)
            assert proc.poll() is None, proc.stderr.read() if proc.stderr else ""
            yield master
        finally:
            proc.terminate()
            try:
                proc.wait(10)
            except subprocess.TimeoutExpired:
                proc.kill()
                proc.wait()


def run(python: str, env: dict[str, str]) -> dict:
    done = subprocess.run([python, PEER], capture_output=True, text=True, env=env, timeout=120, cwd="/")
    assert done.returncode == 0, done.stderr
    return json.loads(done.stdout.strip().splitlines()[-1])


EXPECTED = {
    "server": True,
    "lookup": ["ok", ["world", "arm", 1.5]],
    "reverse": ["ok", ["arm", "world", -1.5]],
    "can": [True, False],
    "full": ["ok", ["arm", "base", -0.5]],
    "waits": ["ok", ["world", "late", 3.0]],
}


def test_buffer_client_against_our_server(server: str) -> None:
    out = run(sys.executable, {**os.environ, "ROS_MASTER_URI": server, "ROS_HOSTNAME": "localhost"})["client"]
    for key, value in EXPECTED.items():
        assert out[key] == value, key
    assert out["unknown"][:2] == [
        "raise",
        ["LookupException", "TransformException", "Exception", "BaseException"],
    ]
    assert out["unknown"][2].startswith(
        '"nowhere" passed to lookupTransform argument source_frame does not exist'
    )
    assert out["unknown_timeout"] == out["unknown"]


@pytest.mark.ros1
def test_ros1_buffer_client_gets_the_same_answers(server: str) -> None:
    theirs = run(testing.ROS1_PYTHON, testing.ros1_env(server))["client"]
    ours = run(sys.executable, {**os.environ, "ROS_MASTER_URI": server, "ROS_HOSTNAME": "localhost"})[
        "client"
    ]
    for key, value in theirs.items():
        assert ours[key] == value, f"{key}: ours {ours[key]} != {value}"

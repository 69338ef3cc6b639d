"""tf between ninjemys and Debian's real tf2_ros, both ways: a 4-frame chain plus statics, correct to 1e-9."""

from __future__ import annotations

import json
import os
import subprocess
import sys
import time
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pytest

from ninjemys import testing

PEER = str(Path(__file__).with_name("tf_peer.py"))
sys.path.insert(0, str(Path(__file__).parent))
from tf_peer import LINKS, PAIRS, STATIC, values  # noqa: E402

pytestmark = pytest.mark.ros1


def matrix(v):
    """4x4 from (x, y, z, qx, qy, qz, qw) with plain numpy (independent of ninjemys' math)."""
    x, y, z, w = v[3], v[4], v[5], v[6]
    m = np.identity(4)
    m[:3, :3] = [
        [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
        [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
        [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
    ]
    m[:3, 3] = v[:3]
    return m


def expected(target: str, source: str) -> np.ndarray:
    parent = {child: (p, matrix(values((p, child)))) for p, child in LINKS + STATIC}

    def to_root(frame):
        m = np.identity(4)
        while frame in parent:
            p, link = parent[frame]
            m = link @ m
            frame = p
        return m

    return np.linalg.inv(to_root(target)) @ to_root(source)


def check(result: dict) -> None:
    assert sorted(result) == sorted(f"{t}<-{s}" for t, s in PAIRS)
    for target, source in PAIRS:
        got = matrix(result[f"{target}<-{source}"])
        assert np.allclose(got, expected(target, source), atol=1e-9, rtol=0), (target, source)


@pytest.fixture
def master() -> Iterator[str]:
    with testing.run_master() as uri:
        yield uri


def ours_env(uri: str) -> dict[str, str]:
    env = dict(os.environ)
    env["ROS_MASTER_URI"] = uri
    return env


def start(cmd: list[str], env: dict[str, str], procs: list) -> subprocess.Popen:
    p = subprocess.Popen(cmd, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    procs.append(p)
    return p


@pytest.fixture
def procs() -> Iterator[list]:
    started: list[subprocess.Popen] = []
    yield started
    for p in started:
        testing.kill_tree(p)


def listen(cmd: list[str], env: dict[str, str]) -> tuple[dict, str]:
    done = subprocess.run(cmd, env=env, capture_output=True, text=True, timeout=60)
    assert done.returncode == 0, done.stderr
    return json.loads(done.stdout.strip().splitlines()[-1]), done.stderr


def test_real_tf2_ros_reads_our_broadcasts(master, procs):
    start([sys.executable, PEER, "broadcast", "--accumulate"], ours_env(master), procs)
    result, _ = listen([testing.ROS1_PYTHON, PEER, "listen"], testing.ros1_env(master))
    check(result)


def test_ours_reads_real_broadcasts_and_survives_bad_input(master, procs):
    start([testing.ROS1_PYTHON, PEER, "broadcast", "--bad"], testing.ros1_env(master), procs)
    began = time.monotonic()
    result, stderr = listen([sys.executable, PEER, "listen"], ours_env(master))
    most = 1 + int((time.monotonic() - began) / 10.0)  # the same line may come back after 10 s
    check(result)
    # three bad transforms arrive 20 times a second: each is reported in one line (again after 10 s)
    for needle in (
        "TF_SELF_TRANSFORM",
        'TF_NAN_INPUT: Ignoring transform for child_frame_id "n"',
        'TF_DENORMALIZED_QUATERNION: Ignoring transform for child_frame_id "q"',
    ):
        assert 1 <= stderr.count(needle) <= most, stderr


def test_legacy_tf_listener_reads_real_broadcasts(master, procs):
    start([testing.ROS1_PYTHON, PEER, "broadcast"], testing.ros1_env(master), procs)
    result, _ = listen([sys.executable, PEER, "listen", "--tf"], ours_env(master))
    check(result)


def test_real_legacy_tf_listener_reads_our_broadcasts(master, procs):
    start([sys.executable, PEER, "broadcast"], ours_env(master), procs)
    time.sleep(0.2)
    result, _ = listen([testing.ROS1_PYTHON, PEER, "listen", "--tf"], testing.ros1_env(master))
    check(result)

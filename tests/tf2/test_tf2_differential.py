"""Our tf2 buffer core against Debian's (C++ tf2 behind tf2_py) on the same random operations: inserts in
and out of order, statics, new parents, pruning, lookups at stored, interpolated and latest times, and
every error text. Results must agree to 1e-9, for our fast path and for our reference path (tf2's walk
alone, ``BufferCore(fast=False)``)."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from ninjemys import testing

pytestmark = pytest.mark.ros1

PEER = str(Path(__file__).with_name("tf_diff_peer.py"))
SEEDS = ["1", "2", "3", "4", "5", "6"]


def outcomes(cmd: list[str], env: dict[str, str] | None) -> list:
    done = subprocess.run(cmd + [PEER, *SEEDS], capture_output=True, text=True, env=env, timeout=120)
    assert done.returncode == 0, done.stderr
    return json.loads(done.stdout.strip().splitlines()[-1])


@pytest.mark.parametrize("path", ["fast", "reference"])
def test_same_answers_as_ros1_tf2(path):
    ours = outcomes([sys.executable], {**os.environ, "TF2_PATH": path})
    theirs = outcomes([testing.ROS1_PYTHON], testing.ros1_env("http://localhost:11311"))
    for seed, a_run, b_run in zip(SEEDS, ours, theirs, strict=True):
        assert len(a_run) == len(b_run)
        for a, b in zip(a_run, b_run, strict=True):
            if a[0] == "ok" and b[0] == "ok":
                assert a[1:3] == b[1:3] and a[3][:2] == b[3][:2], (seed, a, b)
                assert a[3][2:] == pytest.approx(b[3][2:], abs=1e-9), (seed, a, b)
            else:
                assert a == b, seed

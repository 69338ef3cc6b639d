"""The most used calls of our ROS 1 library facades against Debian's, on the same inputs: the same
results, or the same exception class and text. Each peer script runs once under each interpreter
and prints JSON; the two outputs must agree."""

from __future__ import annotations

import json
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

from ninjemys import testing

pytestmark = pytest.mark.ros1

HERE = Path(__file__).parent


def run_peer(python: str, name: str, env: dict[str, str]) -> dict:
    done = subprocess.run(
        [python, str(HERE / name)], capture_output=True, text=True, env=env, timeout=120, cwd="/"
    )
    assert done.returncode == 0, done.stderr
    return json.loads(done.stdout.strip().splitlines()[-1])


def normalized(x):
    """ROS 1's generated classes print as ``pkg.msg._Type.Type``, ours as ``pkg.msg.Type``; our
    TypeException is also a TransformException (see test_parity_api's ALLOWED)."""
    if isinstance(x, dict):
        return {k: normalized(v) for k, v in x.items()}
    if isinstance(x, list):
        if len(x) == 3 and x[0] == "raise" and x[1] and x[1][0] == "TypeException":
            return ["raise", ["TypeException"], normalized(x[2])]
        return [normalized(v) for v in x]
    if isinstance(x, str):
        return re.sub(r"\.(msg|srv)\._\w+\.", r".\1.", x)
    return x


def compare(peer: str, master: str = "http://localhost:11311") -> None:
    theirs = normalized(run_peer(testing.ROS1_PYTHON, peer, testing.ros1_env(master)))
    ours_env = {**os.environ, "ROS_MASTER_URI": master, "ROS_HOSTNAME": "localhost"}
    ours = normalized(run_peer(sys.executable, peer, ours_env))
    for section, values in theirs.items():
        for key, value in values.items():
            assert ours[section].get(key) == value, (
                f"{section}.{key}: ours {ours[section].get(key)} != {value}"
            )


def test_tf_and_tf2_calls_match_ros1() -> None:
    compare("parity_tf_peer.py")


def test_message_filters_cache_and_synchronizers_match_ros1() -> None:
    compare("parity_mf_peer.py")


def test_actionlib_clients_and_servers_report_as_ros1() -> None:
    """Each terminal state (succeeded, aborted, preempted, auto-aborted, raising callback, rejected,
    recalled) as SimpleActionClient, ActionClient and the servers' goal handles report it."""
    with testing.run_master() as master:
        compare("parity_actionlib_peer.py", master)

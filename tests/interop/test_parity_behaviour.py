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


def compare(peer: str, with_master: bool = False) -> None:
    """Run ``peer`` under Debian's Python and ours (each with a master of its own when it needs one:
    a parameter one run leaves must not reach the other) and compare every entry."""
    runs = []
    for python in (testing.ROS1_PYTHON, sys.executable):
        if with_master:
            with testing.run_master() as master:
                runs.append(run_peer(python, peer, _env(python, master)))
        else:
            runs.append(run_peer(python, peer, _env(python, "http://localhost:11311")))
    theirs, ours = (normalized(r) for r in runs)
    for section, values in theirs.items():
        for key, value in values.items():
            assert ours[section].get(key) == value, (
                f"{section}.{key}: ours {ours[section].get(key)} != {value}"
            )


def _env(python: str, master: str) -> dict[str, str]:
    if python == testing.ROS1_PYTHON:
        return testing.ros1_env(master)
    return {**os.environ, "ROS_MASTER_URI": master, "ROS_HOSTNAME": "localhost"}


def test_tf_and_tf2_calls_match_ros1() -> None:
    compare("parity_tf_peer.py")


def test_message_filters_cache_and_synchronizers_match_ros1() -> None:
    compare("parity_mf_peer.py")


def test_actionlib_clients_and_servers_report_as_ros1() -> None:
    """Each terminal state (succeeded, aborted, preempted, auto-aborted, raising callback, rejected,
    recalled) as SimpleActionClient, ActionClient and the servers' goal handles report it."""
    compare("parity_actionlib_peer.py", with_master=True)


def test_dynamic_reconfigure_encoding_server_and_client_match_ros1() -> None:
    """Debian's generated TestConfig: the encoded messages byte for byte, the decoded dicts, and a
    Server and Client talking (updates, clamping, what the callback receives, the descriptions)."""
    compare("parity_dynreconf_peer.py", with_master=True)


#: instance attributes of ROS 1's objects that ours deliberately lack: object.attribute -> reason
INSTANCE_ALLOWED = {
    "SimpleActionServer.terminate_mutex": "ROS 1's lock around its execute thread's stop flag; ours uses a condition",
    "ActionClient.manager": "ours keeps the goals inside ActionClient, with no GoalManager object",
    "Buffer.CAN_TRANSFORM_POLLING_SCALE": "ours waits on the buffer's condition instead of polling",
    "TransformListener.last_update": "the time-jump check's state, internal (check_for_reset uses it)",
    "TransformListener.last_update_lock": "the lock of that state",
    "ApproximateTimeSynchronizer.last_added": "the headerless stamp counter, internal",
    "StatusTracker.id_generator": "ids of goals without one come from the server's generator, not each tracker's",
}


def test_instances_carry_ros1s_attributes() -> None:
    """The attributes ROS 1's constructors set (``client.action_client``, ``buffer.registration`` ...)
    are there on ours too, as attributes or properties."""
    runs = []
    for python in (testing.ROS1_PYTHON, sys.executable):
        with testing.run_master() as master:
            runs.append(run_peer(python, "parity_instances_peer.py", _env(python, master)))
    theirs, ours = runs
    missing = [
        f"{name}.{attr}"
        for name, attrs in theirs.items()
        for attr in attrs["own"]
        if attr not in ours[name]["reachable"] and f"{name}.{attr}" not in INSTANCE_ALLOWED
    ]
    assert not missing, missing


def test_tf_in_a_running_node_matches_ros1() -> None:
    """Broadcasters feeding listeners: lookups that wait for data, the errors when it never comes,
    the static broadcaster keeping every frame, tf.TransformListener's waitForTransform."""
    compare("parity_tf_live_peer.py", with_master=True)


def test_point_cloud2_matches_ros1() -> None:
    """sensor_msgs.point_cloud2: created clouds byte for byte, and every way of reading points back."""
    compare("parity_pc2_peer.py")

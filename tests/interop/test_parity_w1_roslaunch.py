"""roslaunch's Python API against Debian's: rlutil (run id from the master, launch argument
resolution and its errors), ROSLaunchParent launching a file with arguments and an XML string
(parameters set, nodes up, gone after shutdown), scriptapi.ROSLaunch launching and stopping a node,
core.Node's checks and attributes."""

from __future__ import annotations

import pytest
from test_parity_behaviour import compare

pytestmark = pytest.mark.ros1


def test_roslaunch_api_matches_ros1() -> None:
    compare("parity_w1_roslaunch_peer.py", with_master=True)


#: a script launching with no master running: ROSLaunchParent starts one (``/run_id`` set to the
#: script's uuid), the node talks to it, and shutdown() stops the node and then the master
NO_MASTER = r"""
import json
import sys
import time

import rosgraph
import roslaunch.parent
import roslaunch.rlutil

master = rosgraph.Master("/w1peer")
out = {"before": master.is_online()}
uuid = roslaunch.rlutil.get_or_generate_uuid(None, False)
parent = roslaunch.parent.ROSLaunchParent(
    uuid, [], roslaunch_strs=['<launch><param name="/w1/p" value="7"/></launch>'], show_summary=False
)
parent.start(auto_terminate=False)
out["during"] = [master.is_online(), master.getParam("/run_id") == uuid, master.getParam("/w1/p")]
parent.shutdown()
deadline = time.time() + 30
while master.is_online() and time.time() < deadline:
    time.sleep(0.05)
out["after"] = master.is_online()
print(json.dumps(out))
"""


def test_parent_starts_and_stops_a_master_like_ros1() -> None:
    import os
    import subprocess
    import sys

    from ninjemys import testing

    results = []
    for python in (testing.ROS1_PYTHON, sys.executable):
        uri = f"http://localhost:{testing.free_port()}/"
        env = (
            testing.ros1_env(uri)
            if python == testing.ROS1_PYTHON
            else {**os.environ, "ROS_MASTER_URI": uri, "ROS_HOSTNAME": "localhost"}
        )
        done = subprocess.run(
            [python, "-c", NO_MASTER], capture_output=True, text=True, env=env, timeout=120, cwd="/"
        )
        assert done.returncode == 0, done.stderr
        results.append(done.stdout.strip().splitlines()[-1])
    theirs, ours = results
    assert ours == theirs
    assert ours == '{"before": false, "during": [true, true, 7], "after": false}'

"""``import actionlib`` after ``rospy.init_node``: ROS 1's names, signatures and parameters."""

from __future__ import annotations

import os
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path

import pytest

from ninjemys.testing import run_master

PROGRAM = r"""
import rospy, actionlib
from actionlib.msg import TwoIntsAction, TwoIntsGoal, TwoIntsResult
from actionlib_msgs.msg import GoalStatus

rospy.init_node("facade")  # run with __ns:=/facade
rospy.set_param("/actionlib_status_frequency", 20.0)
rospy.set_param("actionlib_server_pub_queue_size", 7)
rospy.set_param("actionlib_client_sub_queue_size", 3)
rospy.set_param("add/status_list_timeout", 2.5)

def execute(goal):
    server.publish_feedback(actionlib.msg.TwoIntsFeedback())
    server.set_succeeded(TwoIntsResult(sum=goal.a + goal.b), "summed")

server = actionlib.SimpleActionServer("add", TwoIntsAction, execute, auto_start=False)
server.start()
client = actionlib.SimpleActionClient("add", TwoIntsAction)
assert client.wait_for_server(rospy.Duration(10))
state = client.send_goal_and_wait(TwoIntsGoal(a=2, b=3), rospy.Duration(10))
print("state", actionlib.GoalStatus.to_string(state), client.get_result().sum, client.get_goal_status_text())
print("names", actionlib.SimpleGoalState.DONE, actionlib.CommState.to_string(actionlib.CommState.DONE),
      actionlib.TerminalState.SUCCEEDED == GoalStatus.SUCCEEDED, actionlib.ActionException.__name__)
inner = server.action_server
print("params", inner.status_frequency, inner.pub_queue_size, inner.status_list_timeout.to_sec(),
      client.action_client.sub_queue_size, inner.ns)
print("topics", sorted(t for t, _ in rospy.get_published_topics() if t.startswith("/facade/add/")))
gen = actionlib.GoalIDGenerator()
print("goal_id", gen.generate_ID().id.startswith("/facade/facade-"))
try:
    actionlib.SimpleActionClient("x", TwoIntsGoal)
except actionlib.ActionException as exc:
    print("not an action:", exc)
"""


@pytest.fixture
def env(tmp_path: Path) -> Iterator[dict[str, str]]:
    env = dict(os.environ, ROS_HOME=str(tmp_path), ROS_HOSTNAME="localhost")
    env.pop("ROS_NAMESPACE", None)
    with run_master(env=env) as uri:
        env["ROS_MASTER_URI"] = uri
        yield env


def test_facade_after_init_node(env: dict[str, str], tmp_path: Path) -> None:
    script = tmp_path / "facade.py"
    script.write_text(PROGRAM)
    done = subprocess.run(
        [sys.executable, str(script), "__ns:=/facade"], env=env, capture_output=True, text=True, timeout=60
    )
    assert done.returncode == 0, done.stderr
    lines = dict(line.split(" ", 1) for line in done.stdout.splitlines())
    assert lines["state"] == "SUCCEEDED 5 summed"
    assert lines["names"] == "2 DONE True ActionException"
    assert lines["params"] == "20.0 7 2.5 3 /facade/add"
    assert lines[
        "topics"
    ] == "['/facade/add/feedback', '/facade/add/goal', '/facade/add/result', '/facade/add/status']" or (
        "'/facade/add/status'" in lines["topics"]
    )
    assert lines["goal_id"] == "True"
    assert lines["not"].startswith("an action: Type is not an action spec")


def test_import_actionlib_loads_nothing_until_used() -> None:
    code = (
        "import sys, actionlib\n"
        "assert 'actionlib.action_client' not in sys.modules\n"
        "assert 'SimpleActionClient' in dir(actionlib)\n"
        "from actionlib import SimpleActionServer, ServerGoalHandle, GoalStatus\n"
        "print(GoalStatus.to_string(GoalStatus.PREEMPTED))\n"
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == "PREEMPTED"

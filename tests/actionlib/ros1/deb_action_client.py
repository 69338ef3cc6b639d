"""Debian's real actionlib client (run under /usr/bin/python3), driven by command-line mode.

Prints one line ``RESULT <json>`` at the end; the test reads it.
  goals NS N      N goals back to back on one SimpleActionClient, each right after wait_for_server

A goal is *lost* when its result never reaches the client. Separately counted: goals whose result
arrived (the goal handle is DONE) but that SimpleActionClient itself missed, because the transitions
came in before ``send_goal`` stored the handle ("Got a transition callback on a goal handle that we're
not tracking": actionlib#126, a race inside the real client that a fast server exposes).
  fresh NS K      K fresh SimpleActionClients, each sending one goal right after wait_for_server
  cancel NS       a long goal, cancelled once active (SimpleActionClient.cancel_goal)
  preempt NS      ActionClient: a long goal, then a second one that the simple server takes instead
  wrong NS        wait_for_server(1 s) on a name nobody serves
  stamps NS       ActionClient: 4 goals, cancel_goals_at_and_before_time(stamp of the 2nd), then
                  cancel_all_goals; the statuses after each step
"""

import json
import sys
import time

import actionlib
import rospy
from actionlib.msg import TwoIntsAction, TwoIntsGoal
from actionlib_msgs.msg import GoalStatus

LONG = -1  # the servers of these tests keep a goal with a == -1 running until it is preempted


def wait_result(client, seconds):
    """``"ok"``, ``"missed"`` (result arrived, the simple client dropped it: #126) or ``"lost"``."""
    deadline = time.time() + seconds
    while time.time() < deadline:
        if client.wait_for_result(rospy.Duration(0.05)):
            return "ok"
        if client.gh is not None and client.gh.get_comm_state() == actionlib.CommState.DONE:
            if client.wait_for_result(rospy.Duration(0.05)):
                return "ok"
            return "missed"
    return "lost"


def main():
    mode, ns = sys.argv[1], sys.argv[2]
    rospy.init_node("real_client", anonymous=True)
    out = {}
    if mode == "goals":
        client = actionlib.SimpleActionClient(ns, TwoIntsAction)
        lost, wrong, missed = [], [], []
        for i in range(int(sys.argv[3])):
            if not client.wait_for_server(rospy.Duration(10)):
                lost.append(i)
                continue
            client.send_goal(TwoIntsGoal(a=i, b=1))
            outcome = wait_result(client, 10)
            if outcome == "lost":
                lost.append(i)
            elif outcome == "missed":
                missed.append(i)
            if outcome != "lost" and (
                client.get_result().sum != i + 1 or client.get_state() != GoalStatus.SUCCEEDED
            ):
                wrong.append(i)
        out = {"lost": lost, "wrong": wrong, "missed": len(missed)}
    elif mode == "fresh":
        lost = []
        for i in range(int(sys.argv[3])):
            client = actionlib.SimpleActionClient(ns, TwoIntsAction)
            if not client.wait_for_server(rospy.Duration(10)):
                lost.append(i)
                continue
            client.send_goal(TwoIntsGoal(a=i, b=1))
            if wait_result(client, 10) == "lost" or client.get_result().sum != i + 1:
                lost.append(i)
            client.action_client.stop()
        out = {"lost": lost}
    elif mode == "cancel":
        client = actionlib.SimpleActionClient(ns, TwoIntsAction)
        client.wait_for_server(rospy.Duration(10))
        client.send_goal(TwoIntsGoal(a=LONG, b=0))
        deadline = time.time() + 10
        while client.get_state() != GoalStatus.ACTIVE and time.time() < deadline:
            time.sleep(0.01)
        client.cancel_goal()
        finished = client.wait_for_result(rospy.Duration(10))
        out = {"finished": finished, "state": client.get_state(), "text": client.get_goal_status_text()}
    elif mode == "preempt":
        client = actionlib.ActionClient(ns, TwoIntsAction)
        client.wait_for_server(rospy.Duration(10))
        first = client.send_goal(TwoIntsGoal(a=LONG, b=0))
        deadline = time.time() + 10
        while first.get_goal_status() != GoalStatus.ACTIVE and time.time() < deadline:
            time.sleep(0.01)
        time.sleep(0.05)
        second = client.send_goal(TwoIntsGoal(a=2, b=3))
        while time.time() < deadline and not (
            first.get_comm_state() == actionlib.CommState.DONE
            and second.get_comm_state() == actionlib.CommState.DONE
        ):
            time.sleep(0.01)
        out = {
            "first": first.get_goal_status(),
            "second": second.get_goal_status(),
            "sum": second.get_result().sum if second.get_result() else None,
        }
    elif mode == "stamps":
        client = actionlib.ActionClient(ns, TwoIntsAction)
        client.wait_for_server(rospy.Duration(10))
        goals = []
        for i in range(4):
            goals.append(client.send_goal(TwoIntsGoal(a=LONG, b=i)))
            time.sleep(0.02)
        deadline = time.time() + 10

        def settle(done):
            while time.time() < deadline and not done():
                time.sleep(0.01)
            return [g.get_goal_status() for g in goals]

        out["accepted"] = settle(lambda: all(g.get_goal_status() == GoalStatus.ACTIVE for g in goals))
        client.cancel_goals_at_and_before_time(goals[1].comm_state_machine.action_goal.goal_id.stamp)
        out["by_stamp"] = settle(
            lambda: all(g.get_comm_state() == actionlib.CommState.DONE for g in goals[:2])
        )
        client.cancel_all_goals()
        out["all"] = settle(lambda: all(g.get_comm_state() == actionlib.CommState.DONE for g in goals))
    elif mode == "wrong":
        client = actionlib.SimpleActionClient(ns, TwoIntsAction)
        out = {"found": client.wait_for_server(rospy.Duration(1))}
    print("RESULT " + json.dumps(out), flush=True)


if __name__ == "__main__":
    main()

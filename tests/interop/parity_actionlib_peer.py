"""actionlib's clients and servers in one node, on actionlib's Test action, printed as JSON (run under
either interpreter, ROS_MASTER_URI set): what SimpleActionClient and ActionClient report in each
terminal state (succeeded, aborted, preempted, auto-aborted, raising callback, rejected, recalled),
and what the servers' goal handles report. Goal ids and stamps vary and are left out."""

import json
import threading
import time

import actionlib
import rospy
from actionlib.msg import TestAction, TestFeedback, TestGoal, TestResult
from actionlib_msgs.msg import GoalStatus

rospy.init_node("parity_actionlib_peer")
server_log = []


def execute(goal):
    kind = goal.goal
    if kind == 1:
        simple.set_succeeded(TestResult(11), "done")
    elif kind == 2:
        simple.set_aborted(TestResult(22), "broken")
    elif kind == 3:
        deadline = time.time() + 10.0
        while not simple.is_preempt_requested() and time.time() < deadline:
            time.sleep(0.01)
        server_log.append(["preempt_requested", simple.is_preempt_requested(), simple.is_active()])
        simple.set_preempted(TestResult(33), "stopped")
    elif kind == 4:
        return  # no terminal state: ROS 1 aborts it, with a warning
    elif kind == 5:
        raise ValueError("boom")
    elif kind == 10:
        # lose the goal as ROS 1's own tests do: through the server's innards
        for i, tracker in enumerate(simple.action_server.status_list):
            if tracker.status.goal_id.id == simple.current_goal.goal.goal_id.id:
                del simple.action_server.status_list[i]
                break
        simple.current_goal = actionlib.ServerGoalHandle()
    elif kind == 9:
        for i in range(3):
            simple.publish_feedback(TestFeedback(i))
            time.sleep(0.05)
        deadline = time.time() + 10.0
        while not simple.is_preempt_requested() and time.time() < deadline:
            time.sleep(0.01)
        simple.set_preempted(TestResult(99), "timed out by the client")


simple = actionlib.SimpleActionServer("simple", TestAction, execute_cb=execute, auto_start=False)
simple.start()

handles = {}


def on_goal(gh):
    kind = gh.get_goal().goal
    handles[kind] = gh
    if kind == 6:
        gh.set_rejected(TestResult(66), "no thanks")
        server_log.append(["rejected", gh.get_goal_status().status, gh.get_goal_status().text])
    elif kind == 8:
        gh.set_accepted("on it")
        server_log.append(["accepted", gh.get_goal_status().status, gh.get_goal_status().text])
        gh.set_succeeded(TestResult(88), "finished")
        server_log.append(["succeeded", gh.get_goal_status().status, gh.get_goal_status().text])
        gh.set_succeeded(TestResult(89), "twice")  # refused: already terminal
        server_log.append(["twice", gh.get_goal_status().status, gh.get_goal_status().text])
    # kind 7 stays pending until cancelled


def on_cancel(gh):
    gh.set_canceled(TestResult(77), "recalled")
    server_log.append(["canceled", gh.get_goal_status().status, gh.get_goal_status().text])


raw = actionlib.ActionServer("raw", TestAction, on_goal, on_cancel, auto_start=False)
raw.start()

callbacks = actionlib.SimpleActionServer("cbs", TestAction, auto_start=False)


def cbs_goal():
    goal = callbacks.accept_new_goal()
    server_log.append(["cbs_accepted", goal.goal, callbacks.is_active(), callbacks.is_preempt_requested()])
    if goal.goal == 1:
        callbacks.set_succeeded(TestResult(10), "quick")


def cbs_preempt():
    server_log.append(["cbs_preempt", callbacks.is_preempt_requested(), callbacks.is_new_goal_available()])
    callbacks.set_preempted(TestResult(30), "made way")


callbacks.register_goal_callback(cbs_goal)
callbacks.register_preempt_callback(cbs_preempt)
callbacks.start()

out = {"simple_client": {}, "action_client": {}, "server": {}}
first = actionlib.SimpleActionClient("cbs", TestAction)
second = actionlib.SimpleActionClient("cbs", TestAction)
first.wait_for_server(rospy.Duration(10.0))
second.wait_for_server(rospy.Duration(10.0))
first.send_goal(TestGoal(3))
deadline = time.time() + 10.0
while first.get_state() != GoalStatus.ACTIVE and time.time() < deadline:
    time.sleep(0.01)
second.send_goal(TestGoal(1))
second.wait_for_result(rospy.Duration(10.0))
first.wait_for_result(rospy.Duration(10.0))
out["simple_client"]["callbacks_first"] = [
    first.get_state(),
    first.get_goal_status_text(),
    first.get_result().result,
]
out["simple_client"]["callbacks_second"] = [
    second.get_state(),
    second.get_goal_status_text(),
    second.get_result().result,
]
client = actionlib.SimpleActionClient("simple", TestAction)
out["simple_client"]["connected"] = client.wait_for_server(rospy.Duration(10.0))
out["simple_client"]["no_goal"] = [client.get_state(), client.get_goal_status_text(), client.get_result()]
out["simple_client"]["simple_state_before"] = client.simple_state


def record(c):
    result = c.get_result()
    return [
        c.get_state(),
        GoalStatus.to_string(c.get_state()) if hasattr(GoalStatus, "to_string") else None,
        c.get_goal_status_text(),
        None if result is None else result.result,
        c.simple_state,
    ]


for kind in (1, 2, 4, 5, 10):
    done = []

    def on_done(state, result, done=done):
        done.append([state, result.result if result else None])

    client.send_goal(TestGoal(kind), done_cb=on_done)
    finished = client.wait_for_result(rospy.Duration(10.0))
    time.sleep(0.1)  # the done callback runs on the result's thread
    out["simple_client"][f"goal_{kind}"] = [finished, record(c=client), done]

active = threading.Event()
client.send_goal(TestGoal(3), active_cb=active.set)
active.wait(10.0)
time.sleep(0.2)
client.cancel_goal()
out["simple_client"]["goal_3"] = [client.wait_for_result(rospy.Duration(10.0)), record(client)]
out["simple_client"]["send_goal_and_wait"] = client.send_goal_and_wait(TestGoal(1), rospy.Duration(10.0))
feedback = []
client.send_goal(TestGoal(9), feedback_cb=lambda fb: feedback.append(type(fb).__name__))
out["simple_client"]["short_wait"] = [
    client.wait_for_result(rospy.Duration(0.05)),
    # PENDING or ACTIVE by then, depending on how soon the server accepted it: a race, not a difference
    client.get_state() in (GoalStatus.PENDING, GoalStatus.ACTIVE),
    client.get_result(),
]
client.wait_for_result(rospy.Duration(0.5))
client.cancel_all_goals()
out["simple_client"]["cancel_all"] = [client.wait_for_result(rospy.Duration(10.0)), record(client)]
out["simple_client"]["feedback_types"] = sorted(set(feedback))
out["simple_client"]["send_goal_and_wait_timeout"] = client.send_goal_and_wait(
    TestGoal(9), rospy.Duration(0.5), rospy.Duration(5.0)
)
out["simple_client"]["after_timeout"] = record(client)
out["simple_client"]["wrong_name"] = actionlib.SimpleActionClient("nowhere", TestAction).wait_for_server(
    rospy.Duration(0.5)
)

ac = actionlib.ActionClient("raw", TestAction)
out["action_client"]["connected"] = ac.wait_for_server(rospy.Duration(10.0))
for kind in (6, 8, 7):
    finished = threading.Event()
    comm = []

    def transition(gh, comm=comm, finished=finished):
        comm.append(actionlib.CommState.to_string(gh.get_comm_state()))
        if gh.get_comm_state() == actionlib.CommState.DONE:
            finished.set()

    gh = ac.send_goal(TestGoal(kind), transition_cb=transition)
    if kind == 7:
        time.sleep(0.5)
        comm_before = gh.get_comm_state()
        gh.cancel()
    finished.wait(10.0)
    result = gh.get_result()
    out["action_client"][f"goal_{kind}"] = [
        finished.is_set(),
        gh.get_goal_status(),
        gh.get_terminal_state(),
        gh.get_goal_status_text(),
        None if result is None else result.result,
        comm,
    ]
out["action_client"]["recall_pending_state"] = actionlib.CommState.to_string(comm_before)
time.sleep(0.3)  # the server's cancel callback logs after publishing the result the client waited for
out["server"]["log"] = server_log
out["server"]["names"] = [
    actionlib.get_name_of_constant(GoalStatus, 3),
    actionlib.get_name_of_constant(actionlib.CommState, 7),
    actionlib.SimpleGoalState.to_string(2),
    actionlib.TerminalState.to_string(9),
    actionlib.get_name_of_constant(GoalStatus, 42),
]
print(json.dumps(out))
rospy.signal_shutdown("done")

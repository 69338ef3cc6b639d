"""Run by Debian's /usr/bin/python3: send move_base goals with ROS 1's real SimpleActionClient.

argv: goals as "x,y,yaw" (map frame). Prints one JSON line per goal: the final state, the status
text and the simulated seconds it took.
"""

import json
import math
import sys

import actionlib
import rospy
from move_base_msgs.msg import MoveBaseAction, MoveBaseGoal

rospy.init_node("ros1_goal_sender", anonymous=True)
client = actionlib.SimpleActionClient("move_base", MoveBaseAction)
if not client.wait_for_server(rospy.Duration(120)):
    print(json.dumps({"error": "no move_base action server"}), flush=True)
    sys.exit(1)


def result_stamp(client):
    """The ROS time move_base stamped on the result (the outcome's instant: the test judges the ground
    truth of that instant, since this script sends the next goal at once), else the time now."""
    try:
        return client.gh.comm_state_machine.latest_result.header.stamp.to_sec()
    except AttributeError:
        return rospy.get_time()


for text in sys.argv[1:]:
    x, y, yaw = (float(v) for v in text.split(","))
    goal = MoveBaseGoal()
    goal.target_pose.header.frame_id = "map"
    goal.target_pose.header.stamp = rospy.Time.now()
    goal.target_pose.pose.position.x = x
    goal.target_pose.pose.position.y = y
    goal.target_pose.pose.orientation.z = math.sin(yaw / 2)
    goal.target_pose.pose.orientation.w = math.cos(yaw / 2)
    feedback = []
    start = rospy.get_time()
    client.send_goal(goal, feedback_cb=feedback.append)
    finished = client.wait_for_result(rospy.Duration(240))
    print(
        json.dumps(
            {
                "goal": [x, y, yaw],
                "finished": finished,
                "state": client.get_state(),
                "text": client.get_goal_status_text(),
                "seconds": rospy.get_time() - start,
                "stamp": result_stamp(client) if finished else rospy.get_time(),
                "feedback": len(feedback),
            }
        ),
        flush=True,
    )
    if not finished:
        client.cancel_goal()

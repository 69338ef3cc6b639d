"""The public instance attributes of the objects ROS 1 programs make (action clients and servers, tf2
buffers, listeners and broadcasters, message_filters, dynamic_reconfigure), printed as JSON (run under
either interpreter, ROS_MASTER_URI set). Attributes set in constructors are part of the API programs
use (``client.action_client``, ``buffer.registration``, ``sub.sub`` ...)."""

import json
import time
import types

import actionlib
import message_filters
import rospy
import tf
import tf2_ros
from actionlib.msg import TestAction, TestGoal, TestResult
from dynamic_reconfigure.client import Client
from dynamic_reconfigure.server import Server
from geometry_msgs.msg import PointStamped

SOURCE = "/usr/lib/python3/dist-packages/dynamic_reconfigure/cfg/TestConfig.py"
cfg = types.ModuleType("TestConfig")
with open(SOURCE) as f:
    exec(compile(f.read(), SOURCE, "exec"), cfg.__dict__)

rospy.init_node("parity_instances_peer")


def public(obj):
    """The object's own public attributes, and what else it answers (properties, methods)."""
    names = (
        vars(obj)
        if hasattr(obj, "__dict__")
        else [n for c in type(obj).__mro__ for n in getattr(c, "__slots__", ())]
    )
    own = sorted(k for k in names if not k.startswith("_"))
    return {"own": own, "reachable": sorted(k for k in dir(obj) if not k.startswith("_"))}


objects = {}
simple_server = actionlib.SimpleActionServer(
    "sas", TestAction, execute_cb=lambda g: simple_server.set_succeeded(TestResult(1)), auto_start=False
)
simple_server.start()
objects["SimpleActionServer"] = simple_server
objects["ActionServer"] = simple_server.action_server
client = actionlib.SimpleActionClient("sas", TestAction)
client.wait_for_server(rospy.Duration(10.0))
objects["SimpleActionClient"] = client
client.send_goal(TestGoal(1))
client.wait_for_result(rospy.Duration(10.0))
objects["ClientGoalHandle"] = client.gh
objects["CommStateMachine"] = client.gh.comm_state_machine
objects["ServerGoalHandle"] = simple_server.current_goal
objects["StatusTracker"] = simple_server.current_goal.status_tracker
objects["ActionClient"] = client.action_client
buffer = tf2_ros.Buffer()
objects["Buffer"] = buffer
objects["TransformListener"] = tf2_ros.TransformListener(buffer)
objects["TransformBroadcaster"] = tf2_ros.TransformBroadcaster()
objects["StaticTransformBroadcaster"] = tf2_ros.StaticTransformBroadcaster()
objects["tf.TransformListener"] = tf.TransformListener()
objects["tf.TransformBroadcaster"] = tf.TransformBroadcaster()
sub = message_filters.Subscriber("points", PointStamped)
objects["message_filters.Subscriber"] = sub
objects["Cache"] = message_filters.Cache(sub, 10)
objects["TimeSynchronizer"] = message_filters.TimeSynchronizer(
    [sub, message_filters.Subscriber("b", PointStamped)], 5
)
objects["ApproximateTimeSynchronizer"] = message_filters.ApproximateTimeSynchronizer(
    [sub, message_filters.Subscriber("c", PointStamped)], 5, 0.1
)
server = Server(cfg, lambda config, level: config)
objects["dynamic_reconfigure.Server"] = server
dyn = Client("parity_instances_peer", timeout=10)
time.sleep(0.2)
objects["dynamic_reconfigure.Client"] = dyn
print(json.dumps({name: public(obj) for name, obj in objects.items()}))
dyn.close()
rospy.signal_shutdown("done")

"""roslaunch's Python API from a script, printed as JSON (run under either interpreter against a
fresh master): rlutil's run id and argument resolution, ROSLaunchParent launching a file with
arguments (parameters set, node running, shut down), scriptapi.ROSLaunch launching and stopping a
single node, and the errors of bad input."""

import json
import os
import stat
import sys
import tempfile
import time

import rosgraph
import roslaunch
import roslaunch.core
import roslaunch.parent
import roslaunch.rlutil
import roslaunch.scriptapi

ws = tempfile.mkdtemp()
pkg = os.path.join(ws, "w1launch")
os.makedirs(os.path.join(pkg, "scripts"))
os.makedirs(os.path.join(pkg, "launch"))
with open(os.path.join(pkg, "package.xml"), "w") as f:
    f.write(
        '<?xml version="1.0"?><package format="2"><name>w1launch</name><version>0.0.1</version>'
        "<description>d</description><maintainer email='a@b.c'>m</maintainer><license>BSD</license>"
        "<buildtool_depend>catkin</buildtool_depend></package>\n"
    )
node_path = os.path.join(pkg, "scripts", "w1node.py")
with open(node_path, "w") as f:
    f.write(
        f"#!{sys.executable}\n"
        "import rospy\n"
        "rospy.init_node('w1node')\n"
        "rospy.set_param('/w1/seen/' + rospy.get_name().strip('/').replace('/', '_'), rospy.get_param('~p', 'none'))\n"
        "rospy.spin()\n"
    )
os.chmod(node_path, os.stat(node_path).st_mode | stat.S_IEXEC)
exit_path = os.path.join(pkg, "scripts", "exit3.py")
with open(exit_path, "w") as f:
    f.write(f"#!{sys.executable}\nimport sys\nsys.exit(3)\n")
os.chmod(exit_path, os.stat(exit_path).st_mode | stat.S_IEXEC)
launch_path = os.path.join(pkg, "launch", "w1.launch")
with open(launch_path, "w") as f:
    f.write(
        '<launch><arg name="val" default="d"/><param name="/w1/launched" value="$(arg val)"/>'
        '<node pkg="w1launch" type="w1node.py" name="a"><param name="p" value="$(arg val)"/></node></launch>\n'
    )
os.environ["ROS_PACKAGE_PATH"] = ws + ":" + os.environ.get("ROS_PACKAGE_PATH", "")
master = rosgraph.Master("/w1peer")


def attempt(f, *args, **kw):
    try:
        return ["ok", f(*args, **kw)]
    except Exception as exc:  # noqa: BLE001
        return ["raise", [type(exc).__name__], str(exc).replace(ws, "WS")]


def wait_param(name, timeout=30.0):
    deadline = time.time() + timeout
    while time.time() < deadline:
        if master.hasParam(name):
            return master.getParam(name)
        time.sleep(0.05)
    return "timed out"


def node_up(name):
    try:
        master.lookupNode(name)
        return True
    except rosgraph.MasterError:
        return False


def wait_gone(name, timeout=30.0):
    deadline = time.time() + timeout
    while node_up(name) and time.time() < deadline:
        time.sleep(0.05)
    return not node_up(name)


out = {"rlutil": {}, "parent": {}, "script": {}, "errors": {}}
uuid = roslaunch.rlutil.get_or_generate_uuid(None, False)
out["rlutil"]["uuid"] = [
    uuid == master.getParam("/run_id"),
    roslaunch.rlutil.get_or_generate_uuid("given", False),
]
out["rlutil"]["dead_master_uuid"] = len(roslaunch.core.generate_run_id())
out["rlutil"]["resolve"] = [
    [
        a.replace(ws, "WS")
        for a in roslaunch.rlutil.resolve_launch_arguments(["w1launch", "w1.launch", "val:=x"])
    ],
    [a.replace(ws, "WS") for a in roslaunch.rlutil.resolve_launch_arguments([launch_path, "val:=y"])],
    roslaunch.rlutil.resolve_launch_arguments([]),
    attempt(roslaunch.rlutil.resolve_launch_arguments, ["w1launch", "none.launch"]),
    attempt(roslaunch.rlutil.resolve_launch_arguments, ["nopkg", "none.launch"]),
    attempt(roslaunch.rlutil.resolve_launch_arguments, ["none.launch"]),
]
roslaunch.configure_logging(uuid)

parent = roslaunch.parent.ROSLaunchParent(uuid, [(launch_path, ["val:=x"])])
parent.start()
out["parent"]["params"] = [wait_param("/w1/seen/a"), master.getParam("/w1/launched"), master.getParam("/a/p")]
out["parent"]["running"] = node_up("/a")
parent.shutdown()
out["parent"]["stopped"] = wait_gone("/a")

strs = roslaunch.parent.ROSLaunchParent(
    uuid,
    [],
    roslaunch_strs=['<launch><node pkg="w1launch" type="w1node.py" name="s" args="_p:=fromstr"/></launch>'],
)
strs.start()
out["parent"]["from_string"] = wait_param("/w1/seen/s")
strs.shutdown()
out["parent"]["from_string_stopped"] = wait_gone("/s")


class Listener:
    def __init__(self):
        self.died = []

    def process_died(self, name, exit_code):
        self.died.append([name, exit_code])


listener = Listener()
quick = roslaunch.parent.ROSLaunchParent(
    uuid,
    [],
    roslaunch_strs=['<launch><node pkg="w1launch" type="exit3.py" name="quick"/></launch>'],
    process_listeners=[listener],
)
quick.start()
quick.spin()
out["parent"]["listener"] = listener.died

launch = roslaunch.scriptapi.ROSLaunch()
out["errors"]["before_start"] = attempt(launch.launch, roslaunch.core.Node("w1launch", "w1node.py", name="b"))
launch.start()
out["errors"]["not_a_node"] = attempt(launch.launch, "w1node.py")
proc = launch.launch(
    roslaunch.core.Node("w1launch", "w1node.py", name="b", namespace="ns1", args="_p:=fromargs")
)
out["script"]["param"] = wait_param("/w1/seen/ns1_b")
out["script"]["alive"] = [proc.is_alive(), node_up("/ns1/b"), proc.name]
proc.stop()
out["script"]["after_stop"] = [proc.is_alive(), wait_gone("/ns1/b")]
launch.stop()

Node = roslaunch.core.Node
out["errors"]["node"] = [
    attempt(Node, "p", "t", name="a/b")[1:],
    attempt(Node, "", "t")[1:],
    attempt(Node, "p", " ")[1:],
    attempt(Node, "p", "t", respawn=True, required=True)[1:],
    attempt(Node, "p", "t", output="x")[1:],
    attempt(Node, "p", "t", cwd="x")[1:],
]
n = Node("p", "t", namespace="a//b", cwd="ros_home")
out["errors"]["node_attrs"] = [n.namespace, n.cwd, n.name, n.args, n.remap_args, n.output, n.machine_name]
out["errors"]["exports"] = [roslaunch.Node is Node, roslaunch.RLException is roslaunch.core.RLException]
print(json.dumps(out, sort_keys=True))

"""rosnode's Python API, printed as JSON (run under either interpreter against a fresh master): node
names, URIs, ping (alive, unknown, dead), info text, killing a node process, master cleanup."""

import contextlib
import io
import json
import os
import subprocess
import sys
import time

import rosgraph
import rosnode
import rospy
from std_msgs.msg import String


def printed(f, *args, **kw):
    buf = io.StringIO()
    with contextlib.redirect_stdout(buf), contextlib.redirect_stderr(buf):
        r = f(*args, **kw)
    return [buf.getvalue(), r]


VICTIM = "import rospy; rospy.init_node('w1_victim'); rospy.Publisher('/w1/v', rospy.AnyMsg, queue_size=1); rospy.spin()"
victim = subprocess.Popen([sys.executable, "-c", VICTIM])
rospy.init_node("w1_rosnode")
pub = rospy.Publisher("/w1/chatter", String, queue_size=1)
sub = rospy.Subscriber("/w1/chatter", String, lambda m: None)
srv_master = rosgraph.Master("/w1/ghost")
srv_master.registerPublisher("/w1/ghost_topic", "std_msgs/String", "http://localhost:1/")
while "/w1_victim" not in rosnode.get_node_names():
    time.sleep(0.05)

master = rosgraph.Master("/w1peer")
me = rospy.get_node_uri()
out = {"names": {}, "ping": {}, "info": {}, "kill": {}}
out["names"]["all"] = sorted(n for n in rosnode.get_node_names() if n != "/rosout")
out["names"]["ns"] = sorted(rosnode.get_node_names("/w1"))
out["names"]["ns_exact"] = sorted(rosnode.get_node_names("/w1_rosnode"))
out["names"]["api"] = [rosnode.get_api_uri(master, "/w1_rosnode") == me, rosnode.get_api_uri(master, "/none")]
out["names"]["list"] = printed(rosnode.rosnode_listnodes, namespace="/w1")
out["names"]["list_uri"] = printed(rosnode.rosnode_listnodes, namespace="/w1", list_uri=True)
out["names"]["list_all"] = printed(rosnode.rosnode_listnodes, namespace="/w1", list_all=True)
out["names"]["machines"] = "localhost" in rosnode.get_machines_by_nodes()
out["names"]["by_machine"] = sorted(
    n for n in rosnode.get_nodes_by_machine("localhost") if n.startswith("/w1")
)
try:
    rosnode.get_nodes_by_machine("no.such.host.invalid")
except rosnode.ROSNodeException as exc:
    out["names"]["bad_machine"] = [type(exc).__name__, str(exc)]

out["ping"]["alive"] = printed(rosnode.rosnode_ping, "/w1_rosnode", max_count=1)
out["ping"]["unknown"] = printed(rosnode.rosnode_ping, "/none", max_count=1)
out["ping"]["dead"] = printed(rosnode.rosnode_ping, "/w1/ghost", max_count=1)
pinged, unpinged = rosnode.rosnode_ping_all()
out["ping"]["all"] = [sorted(n for n in pinged if n.startswith("/w1")), sorted(unpinged)]

out["info"]["description"] = rosnode.get_node_info_description("/w1_rosnode")
out["info"]["description_unknown"] = rosnode.get_node_info_description("/none")
conn = rosnode.get_node_connection_info_description(me, master)
out["info"]["connection"] = [
    conn.splitlines()[0] == f"Pid: {os.getpid()}",
    "Connections:" in conn,
    " * topic: /w1/chatter" in conn,
]
try:
    rosnode.get_node_connection_info_description("http://localhost:1/", master)
except rosnode.ROSNodeIOException as exc:
    out["info"]["connection_dead"] = str(exc)
quiet = printed(rosnode.rosnode_info, "/w1_rosnode", quiet=True)
out["info"]["info_quiet"] = quiet
out["info"]["info_unknown"] = printed(rosnode.rosnode_info, "none")

out["kill"]["kill"] = rosnode.kill_nodes(["/w1_victim", "/none"])
out["kill"]["exit"] = victim.wait(timeout=30)
deadline = time.time() + 10
while "/w1_victim" in rosnode.get_node_names() and time.time() < deadline:
    time.sleep(0.05)
out["kill"]["gone"] = "/w1_victim" not in rosnode.get_node_names()
out["kill"]["cleanup"] = printed(rosnode.cleanup_master_blacklist, master, ["/w1/ghost"])
out["kill"]["after_cleanup"] = "/w1/ghost" in rosnode.get_node_names()
print(json.dumps(out, sort_keys=True))

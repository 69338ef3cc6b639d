"""rosservice's and rosmsg's Python APIs, printed as JSON (run under either interpreter against a
fresh master): the service list, probed types, URIs, nodes, classes, call_service with good and bad
arguments; definitions as ``rosmsg show`` prints them and package listings."""

import json
import subprocess
import sys

import rosmsg
import rospkg
import rospy
import rosservice
from std_srvs.srv import SetBool, SetBoolResponse, Trigger, TriggerResponse


def attempt(f, *args, **kw):
    try:
        return ["ok", f(*args, **kw)]
    except Exception as exc:  # noqa: BLE001
        return ["raise", [type(exc).__name__], str(exc)]


rospy.init_node("w1_rosservice")
rospy.Service("/w1/set", SetBool, lambda req: SetBoolResponse(success=req.data, message=f"got {req.data}"))
rospy.Service("/w1/sub/trigger", Trigger, lambda req: TriggerResponse(success=True, message="t"))
rospy.Service("/w1/fail", Trigger, lambda req: 1 / 0)

out = {"srv": {}, "call": {}, "msg": {}}
me = "/w1_rosservice"
out["srv"]["list"] = sorted(s for s in rosservice.get_service_list() if s.startswith("/w1"))
out["srv"]["list_ns"] = sorted(rosservice.get_service_list(namespace="/w1/sub"))
out["srv"]["list_node"] = sorted(s for s in rosservice.get_service_list(node=me) if s.startswith("/w1"))
out["srv"]["list_nodes"] = sorted(
    [s, n] for s, n in rosservice.get_service_list(namespace="/w1", include_nodes=True)
)
out["srv"]["list_nodes_node"] = sorted(
    [s, n] for s, n in rosservice.get_service_list(node=me, namespace="/w1", include_nodes=True)
)
out["srv"]["type"] = [rosservice.get_service_type(s) for s in ("/w1/set", "/w1/sub/trigger", "/none")]
out["srv"]["uri"] = [
    rosservice.get_service_uri("/w1/set").startswith("rosrpc://"),
    rosservice.get_service_uri("/none"),
]
out["srv"]["node"] = [rosservice.get_service_node("/w1/set"), rosservice.get_service_node("/none")]
out["srv"]["find"] = sorted(rosservice.rosservice_find("std_srvs/Trigger"))
out["srv"]["class"] = [
    rosservice.get_service_class_by_name("/w1/set")._type,
    attempt(rosservice.get_service_class_by_name, "/none"),
]
out["srv"]["args"] = [rosservice.get_service_args("/w1/set"), rosservice.get_service_args("/w1/sub/trigger")]
out["srv"]["has_args"] = [
    rosservice.has_service_args("/w1/set"),
    rosservice.has_service_args("/w1/sub/trigger"),
]
headers = rosservice.get_service_headers("/w1/set", rosservice.get_service_uri("/w1/set"))
out["srv"]["headers"] = sorted((k, v) for k, v in headers.items() if k in ("type", "md5sum"))
out["srv"]["headers_bad"] = [
    attempt(rosservice.get_service_headers, "/x", "http://localhost:1/"),
    attempt(rosservice.get_service_headers, "/x", "rosrpc://localhost:1"),
]


# call_service starts its own anonymous node, so (in ROS 1 as in ours) it runs in a process that has none
CALLER = r"""
import json
import rospy
import rosservice
from std_srvs.srv import Trigger


def called(*args, **kw):
    try:
        request, response = rosservice.call_service(*args, **kw)
        return ["ok", [str(request), str(response)]]
    except Exception as exc:  # noqa: BLE001
        return ["raise", [type(exc).__name__], str(exc)]


out = {}
out["list_args"] = called("/w1/set", [True])
out["dict_args"] = called("/w1/set", [{"data": False}])
out["with_class"] = called("/w1/sub/trigger", [], service_class=Trigger)
out["too_many"] = called("/w1/set", [True, 2])
out["no_field"] = called("/w1/set", [{"nope": 1}])
bad = called("/w1/set", ["yes"])
out["bad_type"] = bad[:2] + [bad[2].splitlines()[0], bad[2].split("srv file:")[1]]  # our field text is ours
out["unknown"] = called("/none", [])
out["handler_raises"] = called("/w1/fail", [])[:2]
print(json.dumps(out))
"""
done = subprocess.run([sys.executable, "-c", CALLER], capture_output=True, text=True, timeout=60)
out["call"] = (
    json.loads(done.stdout.strip().splitlines()[-1]) if done.returncode == 0 else {"error": done.stderr}
)
out["call"]["in_a_node"] = attempt(rosservice.call_service, "/w1/set", [True])[:2]


def uncommented(text):
    """Our shipped definitions carry no comments (docs/parity.md); the rest must be the file's text."""
    return [line.split("#")[0].rstrip() for line in text.splitlines()]


# Debian installs the .msg files of only a few packages (rosmsg reads files, not generated classes)
for t in ("dynamic_reconfigure/Config", "dynamic_reconfigure/ConfigDescription", "actionlib/TestGoal"):
    out["msg"][t] = [rosmsg.get_msg_text(t), uncommented(rosmsg.get_msg_text(t, raw=True))]
for t in ("std_srvs/SetBool", "std_srvs/Trigger"):
    out["msg"][t] = [rosmsg.get_srv_text(t), uncommented(rosmsg.get_srv_text(t, raw=True))]
out["msg"]["unknown_msg"] = attempt(rosmsg.get_msg_text, "dynamic_reconfigure/Nope")[:2]
out["msg"]["unknown_srv"] = attempt(rosmsg.get_srv_text, "std_srvs/Nope")[:2]
rp = rospkg.RosPack()
out["msg"]["list"] = [
    rosmsg.list_msgs("dynamic_reconfigure"),
    rosmsg.list_srvs("std_srvs"),
    rosmsg.list_msgs("std_srvs"),
]
out["msg"]["list_bad"] = [
    attempt(rosmsg.list_types, "std_srvs", mode="x"),
    attempt(rosmsg.list_msgs, "no_such_pkg")[:2],
]
out["msg"]["search"] = sorted(rosmsg.rosmsg_search(rp, rosmsg.MODE_MSG, "Config"))
out["msg"]["search_srv"] = sorted(rosmsg.rosmsg_search(rp, rosmsg.MODE_SRV, "SetBool"))
out["msg"]["md5"] = [
    rosmsg.rosmsg_md5(rosmsg.MODE_MSG, "std_msgs/String"),
    rosmsg.rosmsg_md5(rosmsg.MODE_SRV, "std_srvs/SetBool"),
    attempt(rosmsg.rosmsg_md5, rosmsg.MODE_MSG, "nope/Nope"),
]
out["msg"]["modes"] = [rosmsg.MODE_MSG, rosmsg.MODE_SRV]
print(json.dumps(out, sort_keys=True))

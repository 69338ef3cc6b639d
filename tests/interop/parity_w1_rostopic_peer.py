"""rostopic's Python API in a running node, printed as JSON (run under either interpreter against a
fresh master): topic types and classes (fields inside topics included), info text, listings, the
field extractors, and the hz/bw/delay meters fed by hand."""

import contextlib
import io
import json
import re
import subprocess
import sys
import time

import rospy
import rostopic
from nav_msgs.msg import Odometry
from std_msgs.msg import Header, String


def attempt(f, *args):
    try:
        r = f(*args)
        return ["ok", r]
    except Exception as exc:  # noqa: BLE001
        return ["raise", [type(exc).__name__], str(exc)]


def printed(f, *args):
    buf = io.StringIO()
    with contextlib.redirect_stdout(buf), contextlib.redirect_stderr(buf):
        r = f(*args)
    return [
        # timings vary, and with them the widths of hz's table (its ==== line follows the widths)
        re.sub(r"=+", "=", re.sub(r" +", " ", re.sub(r"\d+\.\d+(e[+-]\d+)?", "N", buf.getvalue()))),
        r if r is None or isinstance(r, (str, int)) else "value",
    ]


rospy.init_node("w1_rostopic")
pub = rospy.Publisher("/w1/chatter", String, queue_size=1)
odom = rospy.Publisher("/w1/odom", Odometry, queue_size=1)
sub = rospy.Subscriber("/w1/chatter", String, lambda m: None)

out = {"types": {}, "eval": {}, "info": {}, "meters": {}}
for topic in (
    "/w1/chatter",
    "/w1/odom/pose/pose",
    "/w1/odom/pose/pose/position/x",
    "/w1/odom/nope",
    "/none",
    "/w1/odom/",
):
    t, real, fn = rostopic.get_topic_type(topic)
    c = rostopic.get_topic_class(topic)
    out["types"][topic] = [t, real, fn is None, c[0]._type if c[0] else None, c[1]]

msg = Odometry()
msg.pose.pose.position.x = 2.5
msg.pose.covariance = [float(i) for i in range(36)]
for pattern in (
    "/pose/pose/position/x",
    "/pose/covariance[3]",
    "/pose/covariance[1:4]",
    "/pose/covariance[::12]",
    "/pose/nope",
    "/pose/covariance[40]",
    "",
):
    fn = rostopic.msgevalgen(pattern)
    out["eval"][pattern] = printed(lambda: None if fn is None else fn(msg))  # noqa: B023
for pattern in ("/x[", "/x[a]", "/x[1:b]", "/x[1:2:3:4]", "/x[]"):
    out["eval"][pattern] = printed(rostopic.msgevalgen, pattern)

node_api = rospy.get_node_uri()
out["info"]["text"] = rostopic.get_info_text("/w1/chatter").replace(node_api, "API")
out["info"]["unknown"] = attempt(rostopic.get_info_text, "/w1/none")
out["info"]["find"] = rostopic.find_by_type("nav_msgs/Odometry")
pubs, subs = rostopic.get_topic_list()
out["info"]["list"] = [
    sorted(p[:2] + (sorted(p[2]),) for p in part if p[0].startswith("/w1")) for part in (pubs, subs)
]
out["info"]["api"] = [
    rostopic.get_api(rosgraph_master := __import__("rosgraph").Master("/x"), "/w1_rostopic") == node_api,
    rostopic.get_api(rosgraph_master, "/no_node"),
]

hz = rostopic.ROSTopicHz(-1)
out["meters"]["hz_empty"] = [hz.get_hz(), printed(hz.print_hz)]
for _ in range(4):
    hz.callback_hz(String())
    rospy.sleep(0.01)
got = hz.get_hz()
out["meters"]["hz"] = [len(got), got[4], got[0] > 0, got[1] <= got[2], hz.get_hz(), hz.window_size]
hz.callback_hz(String())
out["meters"]["hz_print"] = printed(hz.print_hz)
hz2 = rostopic.ROSTopicHz(2, filter_expr=lambda m: m.data == "y")
for d in ("y", "n", "y", "y", "y"):
    hz2.callback_hz(String(data=d), topic="/a")
    rospy.sleep(0.01)
out["meters"]["hz_filtered"] = [hz2.get_hz("/a")[4], len(hz2.get_times("/a")), hz2.get_hz()]
hz2.callback_hz(String(data="y"), topic="/a")
hz2.callback_hz(String(data="y"), topic="/b")
hz2.callback_hz(String(data="y"), topic="/b")
out["meters"]["hz_table"] = printed(hz2.print_hz, ["/a", "/b"])


class Raw:
    _buff = b"x" * 1500


bw = rostopic.ROSTopicBandwidth()
out["meters"]["bw_one"] = printed(bw.print_bw)
for _ in range(3):
    bw.callback(Raw())
    rospy.sleep(0.01)
out["meters"]["bw"] = [printed(bw.print_bw), bw.window_size, len(bw.sizes)]
delay = rostopic.ROSTopicDelay(-1)
stamped = Odometry()
stamped.header.stamp = rospy.Time.now() - rospy.Duration(1)
for _ in range(3):
    delay.callback_delay(stamped)
got = delay.get_delay()
out["meters"]["delay"] = [got[4], 0.9 < got[0] < 30, delay.get_delay(), printed(delay.print_delay)]
out["meters"]["delay_noheader"] = [delay.callback_delay(String()), len(delay.delays)]  # logs an error
out["meters"]["exceptions"] = [
    issubclass(rostopic.ROSTopicIOException, rostopic.ROSTopicException),
    Header()._has_header,
]
# the meters as rostopic hz/bw wire them: AnyMsg subscribers, the topic as callback argument
live_hz = rostopic.ROSTopicHz(-1)
live_bw = rostopic.ROSTopicBandwidth(10)
rospy.Subscriber("/w1/live", rospy.AnyMsg, live_hz.callback_hz, callback_args="/w1/live")
rospy.Subscriber("/w1/live", rospy.AnyMsg, live_bw.callback)
live = rospy.Publisher("/w1/live", String, queue_size=10)
deadline = time.time() + 20
while live.get_num_connections() < 1 and time.time() < deadline:  # one per subscribing node
    time.sleep(0.05)
for i in range(12):
    live.publish(String(data="x" * i))
    time.sleep(0.02)
deadline = time.time() + 20
while len(live_bw.sizes) < 10 and time.time() < deadline:
    time.sleep(0.05)
got = live_hz.get_hz("/w1/live")
out["meters"]["live"] = [got[4] if got else None, sorted(live_bw.sizes), len(live_bw.times)]

# rostopic pub's publishing functions start a node of their own: in a process without one
PUBLISHER = r"""
import json
import time
import rostopic

out = {}
for bad in ("nope/Nope", "notatype"):
    try:
        rostopic.create_publisher("/w1/pubtest", bad, True)
    except rostopic.ROSTopicException as exc:
        out[bad] = str(exc)
pub, cls = rostopic.create_publisher("w1/pubtest", "std_msgs/String", True)
out["class"] = [cls._type, pub.resolved_name]
for args in (["a", "b"], [{"nope": 1}]):
    try:
        rostopic.publish_message(pub, cls, args, once=True)
    except rostopic.ROSTopicException as exc:
        out[str(args)] = str(exc)
rostopic.publish_message(pub, cls, ["hello"], once=True)
print(json.dumps(out), flush=True)
time.sleep(10)
"""
got = []
rospy.Subscriber("/w1/pubtest", String, lambda m: got.append(m.data))
publisher = subprocess.Popen([sys.executable, "-c", PUBLISHER], stdout=subprocess.PIPE, text=True)
printed_lines = []
line = publisher.stdout.readline()
while line and not line.startswith("{"):
    printed_lines.append(line)
    line = publisher.stdout.readline()
deadline = time.time() + 20
while not got and time.time() < deadline:
    time.sleep(0.05)
publisher.kill()
publisher.wait()
out["publish"] = {"calls": json.loads(line) if line else None, "received": got[:1], "printed": printed_lines}
print(json.dumps(out, sort_keys=True))

"""The rospy facade end to end: real node processes over our roscore."""

from __future__ import annotations

import time
import xmlrpc.client
from pathlib import Path

EXAMPLES = Path(__file__).resolve().parents[2] / "examples" / "rospy"

SPIN_AND_REPORT_THREADS = """
import threading, time, rospy
from std_msgs.msg import String
rospy.init_node("spinner")
rospy.Subscriber("chatter", String, lambda m: None)
print("spinning", flush=True)
rospy.spin()
t0 = time.monotonic()
for t in threading.enumerate():
    if t is not threading.main_thread():
        t.join(1.0)
left = [t.name for t in threading.enumerate() if t is not threading.main_thread()]
print("threads left: %s" % left, flush=True)
"""


def _node_names(master: str) -> list[str]:
    state = xmlrpc.client.ServerProxy(master).getSystemState("/test")[2]
    return sorted({n for group in state for _topic, nodes in group for n in nodes})


def test_examples_talker_listener(run_node) -> None:
    listener = run_node(EXAMPLES / "listener.py")
    talker = run_node(EXAMPLES / "talker.py")
    m = listener.wait_for(
        r"^\[INFO\] \[\d+\.\d{6}\]: (/listener_\d+_\d+) heard: greetings from ninjemys #\d+"
    )
    assert m.group(1).startswith("/listener_")
    talker.wait_for(r"^\[INFO\] \[\d+\.\d{6}\]: greetings from ninjemys #0 at \d+\.\d+")


def test_examples_talker_listener_relay(run_node) -> None:
    relay = run_node(EXAMPLES / "talker_listener.py")
    echo = run_node(
        "import rospy\nfrom std_msgs.msg import String\n"
        "rospy.init_node('echo', anonymous=True)\n"
        "rospy.Subscriber('chatter_2', String, lambda m: print('got', m.data, flush=True))\nrospy.spin()\n"
    )
    run_node(EXAMPLES / "talker.py")
    echo.wait_for(r"^got relayed at \d+\.\d+, last heard: greetings from ninjemys")
    relay.wait_for(r"heard from the talker: greetings")


def test_ctrl_c_ends_spin_within_a_second_without_leftover_threads(run_node) -> None:
    node = run_node(SPIN_AND_REPORT_THREADS)
    node.wait_for("^spinning$")
    time.sleep(0.3)
    start = time.monotonic()
    node.interrupt()
    code = node.wait(5)
    elapsed = time.monotonic() - start
    assert code == 0, node.err
    assert elapsed < 1.0 + 0.5, f"took {elapsed:.2f} s"  # 1 s target plus interpreter exit on a loaded box
    assert node.wait_for(r"^threads left: (.*)$").group(1) == "[]"
    assert not any("Traceback" in line for line in node.err), node.err


def test_ctrl_c_interrupts_rate_sleep_in_seed_style_talker(run_node, master: str) -> None:
    talker = run_node(EXAMPLES / "talker.py")
    talker.wait_for("greetings from ninjemys #1 ")
    mine = [n for n in _node_names(master) if n.startswith(f"/talker_{talker.proc.pid}_")]
    assert mine
    talker.interrupt()
    talker.interrupt()  # terminals and roslaunch often deliver two: the second must not break the exit
    assert talker.wait(5) == 0
    assert not any("Traceback" in line for line in talker.err), talker.err
    # the node unregistered everything before the process exited
    assert not set(mine) & set(_node_names(master))


def test_anonymous_names_are_unique(run_node, master: str) -> None:
    code = "import rospy\nrospy.init_node('twin', anonymous=True)\nprint(rospy.get_name(), flush=True)\nrospy.spin()\n"
    a, b = run_node(code), run_node(code)
    name_a = a.wait_for(r"^(/twin_\d+_\d+)$").group(1)
    name_b = b.wait_for(r"^(/twin_\d+_\d+)$").group(1)
    assert name_a != name_b
    assert a.proc.poll() is None and b.proc.poll() is None


def test_command_line_remapping_name_namespace_and_private_params(run_node) -> None:
    code = """
import rospy
from std_msgs.msg import String
rospy.init_node("orig", anonymous=True)
pub = rospy.Publisher("chatter", String, queue_size=1)
print("name", rospy.get_name(), flush=True)
print("ns", rospy.get_namespace(), flush=True)
print("topic", pub.resolved_name, flush=True)
print("rate", repr(rospy.get_param("~rate")), flush=True)
print("gains", repr(rospy.get_param("~gains")), flush=True)
print("label", repr(rospy.get_param("~label")), flush=True)
import sys
print("myargv", rospy.myargv(), flush=True)
print("uri", rospy.get_node_uri(), flush=True)
"""
    node = run_node(
        code,
        "chatter:=/news",
        "__name:=renamed",
        "__ns:=/robot",
        "_rate:=5",
        "_gains:=[1, 2.5]",
        "_label:='7'",
        "__hostname:=127.0.0.1",
        "extra",
    )
    assert node.wait_for(r"^name (.*)$").group(1) == "/robot/renamed"
    assert node.wait_for(r"^ns (.*)$").group(1) == "/robot/"
    assert node.wait_for(r"^topic (.*)$").group(1) == "/news"
    assert node.wait_for(r"^rate (.*)$").group(1) == "5"
    assert node.wait_for(r"^gains (.*)$").group(1) == "[1, 2.5]"
    assert node.wait_for(r"^label (.*)$").group(1) == "'7'"
    assert node.wait_for(r"^myargv (.*)$").group(1).endswith("'extra']")
    assert node.wait_for(r"^uri (.*)$").group(1).startswith("http://127.0.0.1:")
    assert node.wait(10) == 0


def test_name_collision_shuts_down_the_old_node(run_node) -> None:
    code = """
import sys
import rospy
rospy.init_node("dup")
rospy.on_shutdown(lambda: sys.stdout.write("hook ran\\n"))
print("up", flush=True)
rospy.spin()
sys.stdout.write("spin returned\\n")
"""
    old = run_node(code)
    old.wait_for("^up$")
    new = run_node(code)
    new.wait_for("^up$")
    old.wait_for("^hook ran$")
    old.wait_for("^spin returned$")
    assert old.wait(5) == 0
    assert new.proc.poll() is None


def test_logging_routing_stdout_stderr_file_and_rosout(run_node, node_env) -> None:
    watcher = run_node(
        "import rospy\nfrom rosgraph_msgs.msg import Log\n"
        "rospy.init_node('watch')\n"
        "def cb(m):\n"
        "    if m.name == '/loud':\n"
        "        print('rosout', m.level, m.msg, ','.join(m.topics), m.function, flush=True)\n"
        "rospy.Subscriber('/rosout', Log, cb)\nprint('ready', flush=True)\nrospy.spin()\n"
    )
    watcher.wait_for("^ready$")
    loud = run_node(
        "import rospy\nfrom std_msgs.msg import String\n"
        "rospy.init_node('loud')\npub = rospy.Publisher('chatter', String, queue_size=1)\n"
        "def speak():\n"
        "    rospy.logdebug('m-debug')\n    rospy.loginfo('m-info %d', 1)\n    rospy.logwarn('m-warn')\n"
        "    rospy.logerr('m-error')\n    rospy.logfatal('m-fatal')\n"
        "import time\n"
        "try:\n    while not rospy.is_shutdown():\n        speak()\n        rospy.sleep(0.5)\n"
        "except rospy.ROSInterruptException:\n    pass\n"
    )
    loud.wait_for(r"^\[INFO\] \[\d+\.\d+\]: m-info 1$")
    loud.wait_for(r"^\[WARN\] \[\d+\.\d+\]: m-warn$", stream="err")
    loud.wait_for(r"^\[ERROR\] \[\d+\.\d+\]: m-error$", stream="err")
    loud.wait_for(r"^\[FATAL\] \[\d+\.\d+\]: m-fatal$", stream="err")
    m = watcher.wait_for(r"^rosout 2 m-info 1 (\S+) speak$")
    assert "/chatter" in m.group(1).split(",") and "/rosout" in m.group(1).split(",")
    for level, text in ((4, "m-warn"), (8, "m-error"), (16, "m-fatal")):
        watcher.wait_for(rf"^rosout {level} {text} ")
    loud.interrupt()
    assert loud.wait(5) == 0
    assert not any("m-debug" in line for line in loud.out + loud.err + watcher.out)
    assert not any("m-info" in line for line in loud.err)
    assert not any("m-warn" in line for line in loud.out)
    logs = list((Path(node_env["ROS_HOME"]) / "log").glob("loud-*.log"))
    assert len(logs) == 1
    text = logs[0].read_text()
    for piece in ("[rosout][DEBUG]", "m-debug", "m-info 1", "[rosout][WARNING]", "m-fatal"):
        assert piece in text


def test_services_params_timers_and_wait_for_message(run_node) -> None:
    server = run_node(
        Path(__file__).resolve().parents[2] / "src" / "ninjemys" / "tutorials" / "add_two_ints_server.py"
    )
    server.wait_for("^Ready to add two ints.$")
    code = r"""
import rospy, threading
from std_msgs.msg import String
from rospy_tutorials.srv import AddTwoInts, AddTwoIntsRequest
rospy.init_node("checker")
rospy.wait_for_service("add_two_ints", timeout=10)
add = rospy.ServiceProxy("add_two_ints", AddTwoInts, persistent=True)
print("sum", add(2, 3).sum, add.call(AddTwoIntsRequest(a=10, b=-4)).sum, add(a=1, b=1).sum, flush=True)
try:
    rospy.wait_for_service("no_such_service", timeout=0.3)
except rospy.ROSException as exc:
    print("timeout ok", type(exc).__name__, flush=True)
try:
    rospy.ServiceProxy("no_such_service", AddTwoInts)(1, 2)
except rospy.ServiceException as exc:
    print("service exception ok", flush=True)
rospy.set_param("~p", {"a": 1, "b": [1, 2]})
rospy.set_param("/top", "x")
print("params", rospy.get_param("~p/a"), rospy.get_param("~p"), rospy.has_param("/top"),
      rospy.get_param("missing", 42), flush=True)
print("search", rospy.search_param("top"), flush=True)
print("names", "/checker/p/a" in rospy.get_param_names(), flush=True)
rospy.delete_param("/top")
try:
    rospy.get_param("/top")
except KeyError:
    print("keyerror ok", flush=True)
fired = threading.Event()
events = []
def tick(ev):
    events.append(ev)
    fired.set()
t = rospy.Timer(rospy.Duration(0.05), tick, oneshot=True)
fired.wait(5)
print("timer", type(events[0]).__name__, events[0].current_real > rospy.Time(0), flush=True)
pub = rospy.Publisher("latched", String, queue_size=1, latch=True)
pub.publish(data="kw")
msg = rospy.wait_for_message("latched", String, timeout=5)
print("waited", msg.data, flush=True)
try:
    rospy.wait_for_message("silent", String, timeout=0.2)
except rospy.ROSException as exc:
    print("wfm timeout ok", "timeout exceeded" in str(exc), flush=True)
print("topics", ["/latched", "std_msgs/String"] in rospy.get_published_topics(), flush=True)
code, _, state = rospy.get_master().getSystemState()
print("master", code, flush=True)
"""
    node = run_node(code)
    assert node.wait_for(r"^sum (.*)$").group(1) == "5 6 2"
    assert node.wait_for(r"^timeout ok (\w+)$").group(1) == "ROSException"
    node.wait_for(r"^service exception ok$")
    assert node.wait_for(r"^params (.*)$").group(1) == "1 {'a': 1, 'b': [1, 2]} True 42"
    assert node.wait_for(r"^search (.*)$").group(1) == "/top"
    assert node.wait_for(r"^names (.*)$").group(1) == "True"
    node.wait_for(r"^keyerror ok$")
    assert node.wait_for(r"^timer (.*)$").group(1) == "TimerEvent True"
    assert node.wait_for(r"^waited (.*)$").group(1) == "kw"
    assert node.wait_for(r"^wfm timeout ok (.*)$").group(1) == "True"
    assert node.wait_for(r"^topics (.*)$").group(1) == "True"
    assert node.wait_for(r"^master (.*)$").group(1) == "1"
    assert node.wait(10) == 0, node.err
    server.wait_for(r"^Returning \[2 \+ 3 = 5\]$")


def test_service_client_without_init_node(run_node) -> None:
    tutorials = Path(__file__).resolve().parents[2] / "src" / "ninjemys" / "tutorials"
    server = run_node(tutorials / "add_two_ints_server.py")
    server.wait_for("^Ready to add two ints.$")
    client = run_node(tutorials / "add_two_ints_client.py", "20", "22")
    client.wait_for(r"^Requesting 20\+22$")
    client.wait_for(r"^20 \+ 22 = 42$")
    assert client.wait(10) == 0


def test_publish_before_init_and_errors(run_node) -> None:
    code = r"""
import rospy
from std_msgs.msg import String, Int32
pub = rospy.Publisher("chatter", String, queue_size=1)
try:
    pub.publish("x")
except rospy.ROSException as e:
    print("before init:", e, flush=True)
rospy.init_node("early")
print("resolved", pub.resolved_name, flush=True)
try:
    pub.publish(Int32(3))
except rospy.ROSSerializationException as e:
    print("wrong type:", e, flush=True)
try:
    rospy.init_node("other")
except rospy.ROSException as e:
    print("second init refused", flush=True)
rospy.init_node("early")
pub.unregister()
try:
    pub.publish("x")
except rospy.ROSException as e:
    print("after unregister:", e, flush=True)
rospy.signal_shutdown("done")
print("is_shutdown", rospy.is_shutdown(), flush=True)
try:
    rospy.sleep(1)
except rospy.ROSInterruptException:
    print("sleep interrupted", flush=True)
"""
    node = run_node(code)
    assert "init_node() first" in node.wait_for(r"^before init: (.*)$").group(1)
    assert node.wait_for(r"^resolved (.*)$").group(1) == "/chatter"
    assert "but got [std_msgs/Int32]" in node.wait_for(r"^wrong type: (.*)$").group(1)
    node.wait_for("^second init refused$")
    assert "unregistered" in node.wait_for(r"^after unregister: (.*)$").group(1)
    assert node.wait_for(r"^is_shutdown (.*)$").group(1) == "True"
    node.wait_for("^sleep interrupted$")
    assert node.wait(10) == 0


def test_slow_callback_does_not_block_other_subscriber(run_node) -> None:
    """Different subscriptions run concurrently and the publisher never waits for a slow callback."""
    code = r"""
import rospy, time
from std_msgs.msg import String
rospy.init_node("twosubs")
def slow(m):
    time.sleep(1.0)
fast_count = [0]
def fast(m):
    fast_count[0] += 1
    if fast_count[0] == 20:
        print("fast got 20", flush=True)
rospy.Subscriber("chatter_slow", String, slow, queue_size=1)
rospy.Subscriber("chatter_fast", String, fast, queue_size=100)
slow_pub = rospy.Publisher("chatter_slow", String, queue_size=100)
fast_pub = rospy.Publisher("chatter_fast", String, queue_size=100)
while slow_pub.get_num_connections() < 1 or fast_pub.get_num_connections() < 1:
    rospy.sleep(0.01)
start = time.monotonic()
for i in range(40):
    slow_pub.publish(str(i))
    fast_pub.publish(str(i))
    rospy.sleep(0.01)
print("publishing took %.1f s" % (time.monotonic() - start), flush=True)
rospy.sleep(0.5)
"""
    node = run_node(code)
    node.wait_for("^fast got 20$", timeout=20)
    took = float(node.wait_for(r"^publishing took (\S+) s$").group(1))
    assert took < 5.0  # 40 slow callbacks would take 40 s if the publisher waited for them


def test_any_msg_subscriber_gets_raw_bytes(run_node) -> None:
    code = r"""
import rospy
from std_msgs.msg import String
rospy.init_node("raw_listener")
def cb(msg, extra):
    print("raw", extra, msg._connection_header.get("type"), String.deserialize_from(msg._buff).data, flush=True)
    rospy.signal_shutdown("done")
rospy.Subscriber("chatter", rospy.AnyMsg, cb, callback_args="X")
pub = rospy.Publisher("chatter", String, queue_size=1, latch=True)
pub.publish("payload")
rospy.spin()
"""
    node = run_node(code)
    assert node.wait_for(r"^raw (.*)$").group(1) == "X std_msgs/String payload"
    assert node.wait(10) == 0


def test_shutdown_interrupting_a_sleeping_callback_is_quiet(run_node) -> None:
    code = r"""
import rospy
from std_msgs.msg import String
rospy.init_node("sleepy")
def cb(msg):
    print("in callback", flush=True)
    rospy.sleep(30)
def tick(event):
    rospy.sleep(30)
rospy.Subscriber("nap", String, cb)
rospy.Timer(rospy.Duration(0.01), tick, oneshot=True)
rospy.Publisher("nap", String, queue_size=1, latch=True).publish("zz")
rospy.spin()
"""
    node = run_node(code)
    node.wait_for("^in callback$")
    node.interrupt()
    assert node.wait(5) == 0
    assert not any("Traceback" in line or "Exception" in line for line in node.err), node.err


def test_numpy_msg_publish_and_subscribe(run_node) -> None:
    code = r"""
import numpy, rospy
from rospy.numpy_msg import numpy_msg
from rospy_tutorials.msg import Floats
rospy.init_node("numpy_node")
def cb(msg):
    print("got", type(msg.data).__name__, msg.data.dtype, msg.data.tolist(), flush=True)
    rospy.signal_shutdown("done")
rospy.Subscriber("floats", numpy_msg(Floats), cb)
pub = rospy.Publisher("floats", numpy_msg(Floats), queue_size=10, latch=True)
pub.publish(numpy.array([1.0, 2.5, -3.0], dtype=numpy.float32))
rospy.spin()
"""
    node = run_node(code)
    assert node.wait_for(r"^got (.*)$").group(1) == "ndarray float32 [1.0, 2.5, -3.0]"
    assert node.wait(10) == 0

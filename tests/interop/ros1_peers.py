"""Real ROS 1 peers for interop tests: rospy scripts under /usr/bin/python3, and one roscpp program
compiled once per machine (cached by source hash) against Debian's libroscpp-dev."""

from __future__ import annotations

import hashlib
import os
import subprocess
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).parents[1] / "node"))


from ninjemys import testing  # noqa: E402
from ninjemys.testing import NodeProcess  # noqa: E402

ROSPY_TALKER = """
import sys, rospy
from std_msgs.msg import String
rospy.init_node('rospy_talker')
latch = sys.argv[1] == 'latched'
pub = rospy.Publisher('/chatter', String, queue_size=10, latch=latch)
print('ready', flush=True)
if latch:
    pub.publish(String('rospy latched'))
    rospy.spin()
rate = rospy.Rate(50)
i = 0
while not rospy.is_shutdown():
    pub.publish(String('rospy %d' % i))
    i += 1
    rate.sleep()
"""

ROSPY_LISTENER = """
import rospy
from std_msgs.msg import String
rospy.init_node('rospy_listener')
rospy.Subscriber('/chatter', String, lambda m: print('got ' + m.data, flush=True))
print('ready', flush=True)
rospy.spin()
"""

ROSPY_IMAGE_PUB = """
import rospy
from sensor_msgs.msg import Image
rospy.init_node('rospy_camera')
pub = rospy.Publisher('/image', Image, queue_size=1, latch=True)
data = bytes(range(256)) * (1920 * 1080 * 3 // 256)
pub.publish(Image(height=1080, width=1920, encoding='rgb8', step=1920 * 3, data=data))
print('ready', flush=True)
rospy.spin()
"""

ROSPY_IMAGE_SUB = """
import hashlib, rospy
from sensor_msgs.msg import Image
rospy.init_node('rospy_viewer')
def cb(m):
    print('image %dx%d %s %d %s' % (m.width, m.height, m.encoding, len(m.data), hashlib.md5(m.data).hexdigest()), flush=True)
rospy.Subscriber('/image', Image, cb)
print('ready', flush=True)
rospy.spin()
"""

ROSPY_SERVICE = """
import rospy
from std_srvs.srv import Trigger, TriggerResponse
rospy.init_node('rospy_server')
def handle(req):
    return TriggerResponse(True, 'rospy says hi')
rospy.Service('/rospy_trigger', Trigger, handle)
print('ready', flush=True)
rospy.spin()
"""

ROSPY_CLIENT = """
import sys, rospy
from std_srvs.srv import Trigger
rospy.init_node('rospy_client', anonymous=True)
rospy.wait_for_service('/ninjemys_trigger', timeout=10)
persistent = sys.argv[1] == 'persistent'
proxy = rospy.ServiceProxy('/ninjemys_trigger', Trigger, persistent=persistent)
for i in range(3):
    r = proxy()
    print('response %s %s' % (r.success, r.message), flush=True)
try:
    rospy.ServiceProxy('/ninjemys_failing', Trigger)()
except rospy.ServiceException as exc:
    print('error ' + str(exc), flush=True)
"""

ROSCPP_SOURCE = r"""
#include <ros/ros.h>
#include <std_msgs/String.h>
#include <std_srvs/Trigger.h>
#include <cstdint>
#include <cstdio>
#include <string>
static void on_msg(const std_msgs::String::ConstPtr& m) { std::printf("got %s\n", m->data.c_str()); std::fflush(stdout); }
static bool on_trigger(std_srvs::Trigger::Request&, std_srvs::Trigger::Response& res) {
  res.success = true; res.message = "roscpp says hi"; return true;
}
int main(int argc, char** argv) {
  ros::init(argc, argv, "roscpp_node");
  std::string mode = argc > 1 ? argv[1] : "talker";
  ros::NodeHandle nh;
  if (mode == "listener") {
    ros::Subscriber s = nh.subscribe("/chatter", 100, on_msg, ros::TransportHints().tcpNoDelay());
    std::printf("ready\n"); std::fflush(stdout);
    ros::spin();
  } else if (mode == "bigtalker") {
    ros::Publisher p = nh.advertise<std_msgs::String>("/big", 1, true);
    std_msgs::String m; m.data.resize(6220800);
    for (size_t i = 0; i < m.data.size(); i++) m.data[i] = (char)('a' + i % 26);
    p.publish(m);
    std::printf("ready\n"); std::fflush(stdout);
    ros::spin();
  } else if (mode == "biglistener") {
    boost::function<void(const std_msgs::String::ConstPtr&)> cb = [](const std_msgs::String::ConstPtr& m) {
      uint32_t h = 0;
      for (unsigned char c : m->data) h = h * 31u + c;
      std::printf("big %zu %u\n", m->data.size(), h); std::fflush(stdout);
    };
    ros::Subscriber s = nh.subscribe<std_msgs::String>("/big", 1, cb);
    std::printf("ready\n"); std::fflush(stdout);
    ros::spin();
  } else if (mode == "client") {
    if (!ros::service::waitForService("/ninjemys_trigger", 10000)) return 2;
    ros::ServiceClient c = nh.serviceClient<std_srvs::Trigger>("/ninjemys_trigger", true);
    for (int i = 0; i < 3; i++) {
      std_srvs::Trigger t;
      if (!c.call(t)) { std::printf("call failed\n"); return 3; }
      std::printf("response %s %s\n", t.response.success ? "True" : "False", t.response.message.c_str());
    }
    std::fflush(stdout);
    ros::ServiceClient f = nh.serviceClient<std_srvs::Trigger>("/ninjemys_failing");
    std_srvs::Trigger t;
    std::printf("failing call %s\n", f.call(t) ? "succeeded" : "failed");
    std::fflush(stdout);
  } else if (mode == "service") {
    ros::ServiceServer s = nh.advertiseService("/cpp_trigger", on_trigger);
    std::printf("ready\n"); std::fflush(stdout);
    ros::spin();
  } else {
    bool latched = mode == "latched";
    ros::Publisher p = nh.advertise<std_msgs::String>("/chatter", 10, latched);
    std::printf("ready\n"); std::fflush(stdout);
    if (latched) { std_msgs::String m; m.data = "roscpp latched"; p.publish(m); ros::spin(); return 0; }
    ros::Rate r(50); int i = 0;
    while (ros::ok()) { std_msgs::String m; m.data = "roscpp " + std::to_string(i++); p.publish(m); r.sleep(); }
  }
  return 0;
}
"""


def roscpp_binary() -> str:
    """Build (once per source version, shared by all test processes) and return the roscpp program."""
    digest = hashlib.sha256(ROSCPP_SOURCE.encode()).hexdigest()[:16]
    cache = Path(tempfile.gettempdir()) / f"ninjemys-roscpp-{digest}"
    binary = cache / "node"
    if binary.exists():
        return str(binary)
    cache.mkdir(parents=True, exist_ok=True)
    src = cache / f"node-{os.getpid()}.cpp"
    src.write_text(ROSCPP_SOURCE)
    tmp = cache / f"node-{os.getpid()}.tmp"
    libs = [
        "-lroscpp",
        "-lrosconsole",
        "-lroscpp_serialization",
        "-lrostime",
        "-lcpp_common",
        "-lboost_system",
    ]
    subprocess.run(
        ["g++", "-O1", "-o", str(tmp), str(src), *libs, "-lpthread"], check=True, capture_output=True
    )
    os.replace(tmp, binary)  # atomic: concurrent builders never see a half-written binary
    return str(binary)


def rospy(script: str, master_uri: str, *args: str) -> NodeProcess:
    return NodeProcess([testing.ROS1_PYTHON, "-c", script, *args], env=testing.ros1_env(master_uri))


def roscpp(master_uri: str, mode: str) -> NodeProcess:
    return NodeProcess([roscpp_binary(), mode], env=testing.ros1_env(master_uri))

"""C++ nodes on the message packages only ninjemys provides: catkin_make gives control_msgs,
gazebo_msgs, rosserial_msgs ... C++ headers (find_package finds them, and, as on a ROS install,
they are on the include path even when the package does not declare them), a workspace message
that uses one of them gets its own header, and the C++ node talks to Python nodes through our
master both ways, as a service client of a Python server and as a server for a Python client.
The C++ traits carry the md5sums and definitions Python nodes use. One compile per module."""

from __future__ import annotations

import json
import os
import re
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path

import pytest

from ninjemys.packages.cpp_build import find_toolchain
from ninjemys.testing import CatkinWorkspace, kill_tree, ninjemys_bin, run_master

needs_toolchain = pytest.mark.skipif(find_toolchain(os.environ)[0] is None, reason="no C++ toolchain")
# the module's one compile runs inside the first test's time: minutes on a loaded 2-core machine
pytestmark = [pytest.mark.ros1, needs_toolchain, pytest.mark.timeout(900)]

PACKAGE_XML = """<?xml version="1.0"?>
<package format="2">
  <name>msg_bridge</name>
  <version>0.1.0</version>
  <description>A C++ node on ninjemys-only message packages and a workspace message</description>
  <maintainer email="t@example.com">t</maintainer>
  <license>BSD</license>
  <buildtool_depend>catkin</buildtool_depend>
  <depend>roscpp</depend>
  <depend>rospy</depend>
  <depend>std_msgs</depend>
  <depend>control_msgs</depend>
  <depend>gazebo_msgs</depend>
  <build_depend>message_generation</build_depend>
  <exec_depend>message_runtime</exec_depend>
</package>
"""

CMAKE = """cmake_minimum_required(VERSION 3.0.2)
project(msg_bridge)
find_package(catkin REQUIRED COMPONENTS roscpp std_msgs control_msgs gazebo_msgs message_generation)
add_message_files(FILES Report.msg)
add_service_files(FILES Scale.srv)
generate_messages(DEPENDENCIES std_msgs control_msgs)
catkin_package(CATKIN_DEPENDS roscpp std_msgs control_msgs gazebo_msgs message_runtime)
include_directories(${catkin_INCLUDE_DIRS})
add_executable(bridge src/bridge.cpp)
target_link_libraries(bridge ${catkin_LIBRARIES})
add_dependencies(bridge ${catkin_EXPORTED_TARGETS} ${PROJECT_NAME}_generate_messages_cpp)
catkin_install_python(PROGRAMS scripts/py_server.py DESTINATION ${CATKIN_PACKAGE_BIN_DESTINATION})
"""

BRIDGE = r"""// `bridge traits` prints the C++ traits of the types it uses; `bridge` runs the node.
#include <ros/ros.h>
#include <control_msgs/JointControllerState.h>
#include <control_msgs/FollowJointTrajectoryActionGoal.h>
#include <gazebo_msgs/GetModelState.h>
#include <gazebo_msgs/ModelState.h>
#include <msg_bridge/Report.h>
#include <msg_bridge/Scale.h>
#include <rosserial_msgs/Log.h>  // declared nowhere: on the include path as on a ROS install
#include <std_msgs/String.h>
#include <iostream>
#include <sstream>

template <class M> void traits(const char *name) {
  std::cout << "@@msg " << name << " " << ros::message_traits::md5sum<M>() << " "
            << ros::message_traits::datatype<M>() << " " << ros::message_traits::isFixedSize<M>() << " "
            << ros::message_traits::hasHeader<M>() << "\n" << ros::message_traits::definition<M>() << "@@end\n";
}

template <class S> void service(const char *name) {
  std::cout << "@@srv " << name << " " << ros::service_traits::md5sum<S>() << " "
            << ros::service_traits::datatype<S>() << "\n";
}

static ros::Publisher echo;

void heard(const gazebo_msgs::ModelState::ConstPtr &msg) {
  std_msgs::String out;
  std::ostringstream text;
  text << "cpp got " << msg->model_name << " x=" << msg->pose.position.x << " frame=" << msg->reference_frame;
  out.data = text.str();
  echo.publish(out);
}

bool serve(gazebo_msgs::GetModelState::Request &req, gazebo_msgs::GetModelState::Response &res) {
  res.pose.position.x = 4.25;
  res.success = true;
  res.status_message = "cpp served " + req.model_name;
  return true;
}

int main(int argc, char **argv) {
  ros::init(argc, argv, "cpp_bridge");
  if (argc > 1 && std::string(argv[1]) == "traits") {
    traits<control_msgs::JointControllerState>("control_msgs/JointControllerState");
    traits<control_msgs::FollowJointTrajectoryActionGoal>("control_msgs/FollowJointTrajectoryActionGoal");
    traits<gazebo_msgs::ModelState>("gazebo_msgs/ModelState");
    traits<gazebo_msgs::GetModelStateResponse>("gazebo_msgs/GetModelStateResponse");
    traits<rosserial_msgs::Log>("rosserial_msgs/Log");
    traits<msg_bridge::Report>("msg_bridge/Report");
    service<gazebo_msgs::GetModelState>("gazebo_msgs/GetModelState");
    service<msg_bridge::Scale>("msg_bridge/Scale");
    return 0;
  }
  ros::NodeHandle nh;
  ros::Publisher state = nh.advertise<control_msgs::JointControllerState>("cpp_state", 10);
  ros::Publisher report = nh.advertise<msg_bridge::Report>("report", 10);
  ros::Publisher calls = nh.advertise<std_msgs::String>("calls", 10);
  echo = nh.advertise<std_msgs::String>("model_echo", 10);
  ros::Subscriber sub = nh.subscribe("model_in", 10, heard);
  ros::ServiceServer server = nh.advertiseService("cpp/get_model_state", serve);
  std::string answers;
  ros::Rate rate(10);
  for (int count = 0; ros::ok(); ++count) {
    control_msgs::JointControllerState s;
    s.header.stamp = ros::Time::now();
    s.set_point = 1.5;
    s.process_value = 0.25 * count;
    s.command = -2.0;
    state.publish(s);
    msg_bridge::Report r;
    r.header.frame_id = "wheel";
    r.joint = s;
    r.note = "from cpp";
    report.publish(r);
    if (answers.empty() && ros::service::exists("scale", false) &&
        ros::service::exists("gazebo/get_model_state", false)) {
      msg_bridge::Scale scale;
      scale.request.value = 1.5;
      scale.request.factor = 4.0;
      gazebo_msgs::GetModelState get;
      get.request.model_name = "puzzlebot";
      if (ros::service::call("scale", scale) && ros::service::call("gazebo/get_model_state", get)) {
        std::ostringstream text;
        text << "scale=" << scale.response.result << " model x=" << get.response.pose.position.x
             << " status=" << get.response.status_message;
        answers = text.str();
      }
    }
    if (!answers.empty()) {
      std_msgs::String out;
      out.data = answers;
      calls.publish(out);
    }
    ros::spinOnce();
    rate.sleep();
  }
  return 0;
}
"""

PY_SERVER = """#!/usr/bin/env python3
# Serves msg_bridge/Scale (a workspace service) and gazebo_msgs/GetModelState (ninjemys-only).
import rospy
from gazebo_msgs.srv import GetModelState, GetModelStateResponse
from msg_bridge.srv import Scale, ScaleResponse


def get_state(req):
    res = GetModelStateResponse()
    res.pose.position.x = 2.5
    res.success = True
    res.status_message = "python has " + req.model_name
    return res


rospy.init_node("py_server")
rospy.Service("scale", Scale, lambda req: ScaleResponse(req.value * req.factor))
rospy.Service("gazebo/get_model_state", GetModelState, get_state)
rospy.spin()
"""


ACTION_PACKAGE_XML = PACKAGE_XML.replace("msg_bridge", "action_bridge").replace(
    "<depend>gazebo_msgs</depend>", "<depend>actionlib</depend>\n  <depend>trajectory_msgs</depend>"
)

ACTION_CMAKE = """cmake_minimum_required(VERSION 3.0.2)
project(action_bridge)
find_package(catkin REQUIRED COMPONENTS roscpp actionlib control_msgs trajectory_msgs)
catkin_package()
include_directories(${catkin_INCLUDE_DIRS})
add_executable(follow_client src/follow_client.cpp)
target_link_libraries(follow_client ${catkin_LIBRARIES})
catkin_install_python(PROGRAMS scripts/py_arm_controller.py DESTINATION ${CATKIN_PACKAGE_BIN_DESTINATION})
"""

FOLLOW_CLIENT = r"""// A C++ actionlib client of control_msgs/FollowJointTrajectory, as arm code writes it.
#include <ros/ros.h>
#include <actionlib/client/simple_action_client.h>
#include <control_msgs/FollowJointTrajectoryAction.h>
#include <iostream>

typedef actionlib::SimpleActionClient<control_msgs::FollowJointTrajectoryAction> Client;

int main(int argc, char **argv) {
  ros::init(argc, argv, "cpp_follow_client");
  Client client("arm_controller/follow_joint_trajectory", true);
  if (!client.waitForServer(ros::Duration(90))) {
    std::cout << "no server" << std::endl;
    return 1;
  }
  control_msgs::FollowJointTrajectoryGoal goal;
  goal.trajectory.joint_names.push_back("shoulder");
  goal.trajectory.joint_names.push_back("elbow");
  trajectory_msgs::JointTrajectoryPoint point;
  point.positions.push_back(1.0);
  point.positions.push_back(2.0);
  point.time_from_start = ros::Duration(0.5);
  goal.trajectory.points.push_back(point);
  goal.trajectory.points.push_back(point);
  client.sendGoal(goal);
  if (!client.waitForResult(ros::Duration(90))) {
    std::cout << "no result" << std::endl;
    return 1;
  }
  control_msgs::FollowJointTrajectoryResultConstPtr result = client.getResult();
  std::cout << "state " << client.getState().toString() << " error_code " << result->error_code
            << " error_string " << result->error_string << std::endl;
  return 0;
}
"""

PY_ARM_CONTROLLER = """#!/usr/bin/env python3
# A Python FollowJointTrajectory action server (what a simulated arm controller offers).
import actionlib
import rospy
from control_msgs.msg import FollowJointTrajectoryAction, FollowJointTrajectoryResult


def execute(goal):
    result = FollowJointTrajectoryResult()
    result.error_code = FollowJointTrajectoryResult.SUCCESSFUL
    result.error_string = "python moved %s through %d points" % (
        "+".join(goal.trajectory.joint_names), len(goal.trajectory.points))
    server.set_succeeded(result)


rospy.init_node("py_arm_controller")
server = actionlib.SimpleActionServer(
    "arm_controller/follow_joint_trajectory", FollowJointTrajectoryAction, execute, auto_start=False)
server.start()
rospy.spin()
"""


@pytest.fixture(scope="module")
def workspace(tmp_path_factory: pytest.TempPathFactory) -> Path:
    ws = tmp_path_factory.mktemp("cpp_msgs_ws")
    pkg = ws / "src" / "msg_bridge"
    for sub in ("src", "msg", "srv", "scripts"):
        (pkg / sub).mkdir(parents=True)
    (pkg / "package.xml").write_text(PACKAGE_XML)
    (pkg / "CMakeLists.txt").write_text(CMAKE)
    (pkg / "msg" / "Report.msg").write_text(
        "Header header\ncontrol_msgs/JointControllerState joint\nstring note\n"
    )
    (pkg / "srv" / "Scale.srv").write_text("float64 value\nfloat64 factor\n---\nfloat64 result\n")
    (pkg / "src" / "bridge.cpp").write_text(BRIDGE)
    (pkg / "scripts" / "py_server.py").write_text(PY_SERVER)
    (pkg / "scripts" / "py_server.py").chmod(0o755)
    # a second package on actionlib's C++ library (Debian's libactionlib-dev) and control_msgs' actions
    arm = ws / "src" / "action_bridge"
    for sub in ("src", "scripts"):
        (arm / sub).mkdir(parents=True)
    (arm / "package.xml").write_text(ACTION_PACKAGE_XML)
    (arm / "CMakeLists.txt").write_text(ACTION_CMAKE)
    (arm / "src" / "follow_client.cpp").write_text(FOLLOW_CLIENT)
    (arm / "scripts" / "py_arm_controller.py").write_text(PY_ARM_CONTROLLER)
    (arm / "scripts" / "py_arm_controller.py").chmod(0o755)
    env = {k: v for k, v in os.environ.items() if k not in ("ROS_PACKAGE_PATH", "CMAKE_PREFIX_PATH")}
    env.pop("NINJEMYS_CATKIN_CPP", None)
    result = subprocess.run(
        [ninjemys_bin("catkin_make")],
        cwd=ws,
        env=env,
        capture_output=True,
        text=True,
        timeout=900,
        check=False,
    )
    out = result.stdout + result.stderr
    assert result.returncode == 0, out
    assert "msg_bridge: C++ program(s) built by catkin's CMake: bridge" in out, out
    return ws


def _env(ws: Path, master: str = "http://localhost:1") -> dict[str, str]:
    return CatkinWorkspace(ws).env(master)


@pytest.fixture
def master() -> Iterator[str]:
    with run_master() as uri:
        yield uri


def _start(cmd: list[str], env: dict[str, str]) -> subprocess.Popen[str]:
    return subprocess.Popen(
        cmd, env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, start_new_session=True
    )


def _run(
    cmd: list[str], env: dict[str, str], timeout: float = 90, cwd: Path | None = None
) -> subprocess.CompletedProcess[str]:
    return subprocess.run(cmd, env=env, capture_output=True, text=True, timeout=timeout, check=False, cwd=cwd)


def test_headers_are_where_catkin_puts_them(workspace: Path) -> None:
    assert (workspace / "devel" / "include" / "msg_bridge").is_symlink()  # to catkin's generated headers
    assert (workspace / "devel" / "include" / "msg_bridge" / "Report.h").is_file()
    assert (workspace / "devel" / "include" / "msg_bridge" / "Scale.h").is_file()
    shipped = workspace / "build" / "ninjemys_cpp" / "shipped"
    if Path("/usr/share/gazebo_msgs/cmake/gazebo_msgsConfig.cmake").is_file():
        pytest.skip("this machine has gazebo_msgs' own C++ side")
    assert (shipped / "include" / "gazebo_msgs" / "GetModelState.h").is_file()
    assert (shipped / "share" / "control_msgs" / "cmake" / "control_msgsConfig.cmake").is_file()


def test_cpp_traits_are_the_md5sums_and_definitions_python_uses(workspace: Path) -> None:
    env = _env(workspace)
    traits = _run([str(workspace / "devel" / "lib" / "msg_bridge" / "bridge"), "traits"], env)
    assert traits.returncode == 0, traits.stdout + traits.stderr
    blocks = re.findall(r"@@msg (\S+) (\w+) (\S+) (\d) (\d)\n(.*?)@@end\n", traits.stdout, re.S)
    services = dict(re.findall(r"@@srv (\S+) (\w+) \S+\n", traits.stdout))
    assert len(blocks) == 6 and len(services) == 2, traits.stdout
    names = [b[0] for b in blocks]
    script = (
        "import json, sys\nfrom ninjemys.idl import loader\n"
        "out = {n: [loader.get_message_md5(n), loader.get_full_text(n)] for n in sys.argv[1:-2]}\n"
        "out.update({n: [loader.get_service_class(n)._md5sum, ''] for n in sys.argv[-2:]})\n"
        "print(json.dumps(out))\n"
    )
    python = _run([sys.executable, "-c", script, *names, *services], env)
    assert python.returncode == 0, python.stderr
    ours = json.loads(python.stdout)
    for name, md5, datatype, _fixed, _header, definition in blocks:
        assert datatype == name
        assert md5 == ours[name][0], name
        if name.startswith("msg_bridge/"):
            continue  # Debian's gencpp wrote it, with Debian's commented std_msgs/Header text
        full = ours[name][1]
        assert definition == (full if full.endswith("\n") else full + "\n"), name  # every line ends
    assert {b[0]: (b[3], b[4]) for b in blocks}["control_msgs/JointControllerState"] == ("0", "1")
    for name, md5 in services.items():
        assert md5 == ours[name][0], name


def test_cpp_node_publishes_ninjemys_only_and_workspace_messages_to_python(
    workspace: Path, master: str
) -> None:
    env = _env(workspace, master)
    bridge = _start([ninjemys_bin("rosrun"), "msg_bridge", "bridge"], env)
    try:
        state = _run([ninjemys_bin("rostopic"), "echo", "-n", "1", "/cpp_state"], env)
        assert "set_point: 1.5" in state.stdout and "command: -2.0" in state.stdout, (
            state.stdout + state.stderr
        )
        report = _run([ninjemys_bin("rostopic"), "echo", "-n", "1", "/report"], env)
        assert 'frame_id: "wheel"' in report.stdout, report.stdout + report.stderr
        assert "set_point: 1.5" in report.stdout and 'note: "from cpp"' in report.stdout
    finally:
        kill_tree(bridge)


def test_python_publishes_a_ninjemys_only_message_to_the_cpp_node(workspace: Path, master: str) -> None:
    env = _env(workspace, master)
    bridge = _start([ninjemys_bin("rosrun"), "msg_bridge", "bridge"], env)
    pub = _start(
        [
            ninjemys_bin("rostopic"), "pub", "-r", "10", "/model_in", "gazebo_msgs/ModelState",
            "{model_name: puzzlebot, pose: {position: {x: 2.5}}, reference_frame: world}",
        ],
        env,
    )  # fmt: skip
    try:
        heard = _run([ninjemys_bin("rostopic"), "echo", "-n", "1", "/model_echo"], env)
        assert 'data: "cpp got puzzlebot x=2.5 frame=world"' in heard.stdout, heard.stdout + heard.stderr
    finally:
        kill_tree(pub)
        kill_tree(bridge)


def test_services_round_trip_between_cpp_and_python(workspace: Path, master: str) -> None:
    """The C++ node calls a Python server (a workspace service and gazebo_msgs/GetModelState), and
    a Python client calls the C++ node's GetModelState server."""
    env = _env(workspace, master)
    server = _start([ninjemys_bin("rosrun"), "msg_bridge", "py_server.py"], env)
    bridge = _start([ninjemys_bin("rosrun"), "msg_bridge", "bridge"], env)
    try:
        calls = _run([ninjemys_bin("rostopic"), "echo", "-n", "1", "/calls"], env)
        assert 'data: "scale=6 model x=2.5 status=python has puzzlebot"' in calls.stdout, (
            calls.stdout + calls.stderr
        )
        answer = _run(
            [ninjemys_bin("rosservice"), "call", "--wait", "/cpp/get_model_state", "{model_name: turtle}"],
            env,
        )
        assert 'status_message: "cpp served turtle"' in answer.stdout, answer.stdout + answer.stderr
        assert "x: 4.25" in answer.stdout and "success: True" in answer.stdout
    finally:
        kill_tree(bridge)
        kill_tree(server)


def test_a_header_prefix_that_cannot_be_written_is_one_clear_error(tmp_path: Path) -> None:
    pkg = tmp_path / "src" / "tiny_cpp"
    (pkg / "src").mkdir(parents=True)
    (pkg / "package.xml").write_text(PACKAGE_XML.replace("msg_bridge", "tiny_cpp"))
    (pkg / "CMakeLists.txt").write_text(
        "cmake_minimum_required(VERSION 3.0.2)\nproject(tiny_cpp)\nfind_package(catkin REQUIRED COMPONENTS roscpp)\n"
        "catkin_package()\nadd_executable(tiny src/tiny.cpp)\n"
    )
    (pkg / "src" / "tiny.cpp").write_text("int main() { return 0; }\n")
    blocker = tmp_path / "build" / "ninjemys_cpp" / "shipped"
    blocker.parent.mkdir(parents=True)
    blocker.write_text("a file where the prefix goes\n")
    env = {k: v for k, v in os.environ.items() if k not in ("ROS_PACKAGE_PATH", "CMAKE_PREFIX_PATH")}
    env.pop("NINJEMYS_CATKIN_CPP", None)
    result = _run([ninjemys_bin("catkin_make")], env, timeout=600, cwd=tmp_path)
    out = result.stdout + result.stderr
    assert result.returncode != 0 and "Traceback" not in out, out
    assert f"{blocker}: cannot write the C++ message headers" in out, out


def test_cpp_action_client_of_a_python_server_on_control_msgs_actions(workspace: Path, master: str) -> None:
    """control_msgs' action messages (expanded from the .action by ninjemys) work with roscpp's
    actionlib: a C++ SimpleActionClient gets a Python SimpleActionServer's result."""
    client = workspace / "devel" / "lib" / "action_bridge" / "follow_client"
    if not client.exists():
        pytest.skip("actionlib's C++ side (Debian: libactionlib-dev) is not installed")
    env = _env(workspace, master)
    server = _start([ninjemys_bin("rosrun"), "action_bridge", "py_arm_controller.py"], env)
    try:
        result = _run([ninjemys_bin("rosrun"), "action_bridge", "follow_client"], env, timeout=200)
        assert "state SUCCEEDED error_code 0 error_string python moved shoulder+elbow through 2 points" in (
            result.stdout
        ), result.stdout + result.stderr
    finally:
        kill_tree(server)

"""C++ nodes build where a toolchain exists: catkin_make hands the packages with C++ targets to catkin's
own CMake (Debian's catkin, g++, libroscpp-dev, gencpp), links the programs into devel/lib/<pkg>/, and
they talk to Python nodes through ninjemys' master both ways, custom message included."""

from __future__ import annotations

import os
import subprocess
from collections.abc import Iterator
from pathlib import Path

import pytest

from ninjemys.packages.cpp_build import (
    failing_package,
    find_toolchain,
    missing_cpp_dependency,
    missing_definitions_hint,
    noetic_compat_flags,
)
from ninjemys.testing import CatkinWorkspace, kill_tree, ninjemys_bin, run_master

PACKAGE_XML = """<?xml version="1.0"?>
<package format="2">
  <name>cpp_chat</name>
  <version>0.1.0</version>
  <description>C++ chat nodes for the toolchain test</description>
  <maintainer email="t@example.com">t</maintainer>
  <license>BSD</license>
  <buildtool_depend>catkin</buildtool_depend>
  <depend>roscpp</depend>
  <depend>std_msgs</depend>
  <build_depend>message_generation</build_depend>
  <exec_depend>message_runtime</exec_depend>
</package>
"""

CMAKE = """cmake_minimum_required(VERSION 3.0.2)
project(cpp_chat)
find_package(catkin REQUIRED COMPONENTS roscpp std_msgs message_generation)
add_message_files(FILES Reading.msg)
generate_messages(DEPENDENCIES std_msgs)
catkin_package(CATKIN_DEPENDS roscpp std_msgs message_runtime)
include_directories(${catkin_INCLUDE_DIRS})
add_executable(chatter src/chatter.cpp)
target_link_libraries(chatter ${catkin_LIBRARIES})
add_dependencies(chatter ${PROJECT_NAME}_generate_messages_cpp)
add_executable(${PROJECT_NAME}_echo src/echo.cpp)
target_link_libraries(${PROJECT_NAME}_echo ${catkin_LIBRARIES})
catkin_install_python(PROGRAMS scripts/py_listener.py DESTINATION ${CATKIN_PACKAGE_BIN_DESTINATION})
"""

CHATTER = r"""// Publishes "hello N" on /chatter and a cpp_chat/Reading on /reading.
#include <ros/ros.h>
#include <std_msgs/String.h>
#include <cpp_chat/Reading.h>
#include <sstream>

int main(int argc, char **argv) {
  ros::init(argc, argv, "cpp_chatter");
  ros::NodeHandle nh;
  ros::Publisher text = nh.advertise<std_msgs::String>("chatter", 10);
  ros::Publisher reading = nh.advertise<cpp_chat::Reading>("reading", 10);
  ros::Rate rate(20);
  for (int count = 0; ros::ok(); ++count) {
    std_msgs::String msg;
    std::ostringstream out;
    out << "hello " << count;
    msg.data = out.str();
    text.publish(msg);
    cpp_chat::Reading r;
    r.header.stamp = ros::Time::now();
    r.label = "temperature";
    r.value = 20.5 + count;
    reading.publish(r);
    ros::spinOnce();
    rate.sleep();
  }
  return 0;
}
"""

ECHO = r"""// Listens on /chatter and republishes each string, prefixed, on /echo. Written as the Noetic-era
// books and tutorials write class-based nodes: boost::bind(&Class::method, this, _1) with the global
// _1 that Boost 1.71 had (catkin_make must make that compile on newer Boost too).
#include <ros/ros.h>
#include <std_msgs/String.h>

class Echo {
 public:
  Echo() : echo_(nh_.advertise<std_msgs::String>("echo", 10)),
           sub_(nh_.subscribe<std_msgs::String>("chatter", 10, boost::bind(&Echo::heard, this, _1))) {}

 private:
  void heard(const std_msgs::String::ConstPtr &msg) {
    std_msgs::String out;
    out.data = "cpp heard: " + msg->data;
    echo_.publish(out);
  }
  ros::NodeHandle nh_;
  ros::Publisher echo_;
  ros::Subscriber sub_;
};

int main(int argc, char **argv) {
  ros::init(argc, argv, "cpp_echo");
  Echo echo;
  ros::spin();
  return 0;
}
"""

PY_LISTENER = """#!/usr/bin/env python3
# Waits for one cpp_chat/Reading from the C++ node and prints its fields.
import rospy
from cpp_chat.msg import Reading

rospy.init_node("py_reading_listener")
msg = rospy.wait_for_message("reading", Reading, timeout=60)
print("reading", msg.label, msg.value, msg.header.stamp.secs > 0, flush=True)
"""

needs_toolchain = pytest.mark.skipif(find_toolchain(os.environ)[0] is None, reason="no C++ toolchain")


@pytest.fixture(scope="module")
def workspace(tmp_path_factory: pytest.TempPathFactory) -> Path:
    ws = CatkinWorkspace(tmp_path_factory.mktemp("cpp_ws"))
    files = {
        "package.xml": PACKAGE_XML,
        "CMakeLists.txt": CMAKE,
        "msg/Reading.msg": "std_msgs/Header header\nstring label\nfloat64 value\n",
        "src/chatter.cpp": CHATTER,
        "src/echo.cpp": ECHO,
        "scripts/py_listener.py": PY_LISTENER,
    }
    ws.package("cpp_chat", files, executables=["scripts/py_listener.py"])
    result = ws.catkin_make(timeout=600)
    assert result.returncode == 0, result.stdout + result.stderr
    assert "cpp_chat: C++ program(s) built by catkin's CMake: chatter cpp_chat_echo" in result.stdout
    return ws.root


def _env(ws: Path, master: str) -> dict[str, str]:
    return CatkinWorkspace(ws).env(master)


@pytest.fixture
def master() -> Iterator[str]:
    with run_master() as uri:
        yield uri


def _start(cmd: list[str], env: dict[str, str]) -> subprocess.Popen[str]:
    return subprocess.Popen(
        cmd, env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, start_new_session=True
    )


@pytest.mark.ros1
@needs_toolchain
def test_programs_are_linked_where_rosrun_looks(workspace: Path) -> None:
    for name in ("chatter", "cpp_chat_echo"):
        program = workspace / "devel" / "lib" / "cpp_chat" / name
        assert program.is_symlink() and os.access(program.resolve(), os.X_OK)
    assert (workspace / "build" / "ninjemys_cpp" / "devel" / "include" / "cpp_chat" / "Reading.h").is_file()


@pytest.mark.ros1
@needs_toolchain
def test_cpp_talker_custom_message_to_python_listener(workspace: Path, master: str) -> None:
    env = _env(workspace, master)
    talker = _start([ninjemys_bin("rosrun"), "cpp_chat", "chatter"], env)
    try:
        heard = subprocess.run(
            [ninjemys_bin("rosrun"), "cpp_chat", "py_listener.py"],
            env=env, capture_output=True, text=True, timeout=90, check=False,
        )  # fmt: skip
        assert heard.returncode == 0, heard.stdout + heard.stderr
        assert "reading temperature" in heard.stdout and "True" in heard.stdout
        text = subprocess.run(
            [ninjemys_bin("rostopic"), "echo", "-n", "1", "/chatter"],
            env=env, capture_output=True, text=True, timeout=60, check=False,
        )  # fmt: skip
        assert 'data: "hello ' in text.stdout, text.stdout + text.stderr
    finally:
        kill_tree(talker)


@pytest.mark.ros1
@needs_toolchain
def test_python_talker_to_cpp_listener(workspace: Path, master: str) -> None:
    env = _env(workspace, master)
    echo = _start([ninjemys_bin("rosrun"), "cpp_chat", "cpp_chat_echo"], env)
    pub = _start(
        [ninjemys_bin("rostopic"), "pub", "-r", "10", "/chatter", "std_msgs/String", "data: from python"], env
    )
    try:
        heard = subprocess.run(
            [ninjemys_bin("rostopic"), "echo", "-n", "1", "/echo"],
            env=env, capture_output=True, text=True, timeout=60, check=False,
        )  # fmt: skip
        assert 'data: "cpp heard: from python"' in heard.stdout, heard.stdout + heard.stderr
    finally:
        kill_tree(pub)
        kill_tree(echo)


def test_without_a_toolchain_the_reason_is_given(monkeypatch: pytest.MonkeyPatch) -> None:
    assert find_toolchain({"PATH": "/nonexistent"})[1].startswith("no cmake, no a C++ compiler")
    tool, why = find_toolchain({"PATH": os.environ.get("PATH", ""), "NINJEMYS_CATKIN_CPP": "0"})
    assert tool is None and "Python-only" in why


@pytest.mark.ros1
@needs_toolchain
@pytest.mark.skipif(not Path("/usr/bin/catkin_make").exists(), reason="no Debian catkin")
def test_a_compile_error_fails_like_debians_catkin_make(tmp_path: Path) -> None:
    results = {}
    for who, command, env in (
        (
            "debian",
            "/usr/bin/catkin_make",
            {"PATH": "/usr/bin:/bin", "HOME": str(tmp_path), "LANG": "C.UTF-8"},
        ),
        (
            "ours",
            ninjemys_bin("catkin_make"),
            {k: v for k, v in os.environ.items() if k != "ROS_PACKAGE_PATH"},
        ),
    ):
        pkg = tmp_path / who / "src" / "broken_cpp"
        (pkg / "src").mkdir(parents=True)
        (pkg / "package.xml").write_text(PACKAGE_XML.replace("cpp_chat", "broken_cpp"))
        (pkg / "CMakeLists.txt").write_text(
            "cmake_minimum_required(VERSION 3.0.2)\nproject(broken_cpp)\n"
            "find_package(catkin REQUIRED COMPONENTS roscpp)\ncatkin_package()\n"
            "include_directories(${catkin_INCLUDE_DIRS})\nadd_executable(node src/node.cpp)\n"
        )
        (pkg / "src" / "node.cpp").write_text(
            "#include <ros/ros.h>\nint main() { return undeclared_name; }\n"
        )
        env.pop("NINJEMYS_CATKIN_CPP", None)
        results[who] = subprocess.run(
            [command], cwd=tmp_path / who, env=env, capture_output=True, text=True, timeout=600, check=False
        )
    for who, result in results.items():
        assert result.returncode != 0, who
        assert "undeclared_name" in result.stdout + result.stderr, who
    assert 'Invoking "make -j' in results["ours"].stdout + results["ours"].stderr


def test_newer_boost_gets_noetics_global_placeholders(tmp_path: Path) -> None:
    header = tmp_path / "version.hpp"
    header.write_text("#define BOOST_VERSION 107400\n")
    assert noetic_compat_flags(header) == "-DBOOST_BIND_GLOBAL_PLACEHOLDERS -include boost/bind.hpp"
    header.write_text("#define BOOST_VERSION 107100\n")
    assert noetic_compat_flags(header) == ""
    assert noetic_compat_flags(tmp_path / "absent.hpp") == ""


def test_message_definitions_missing_for_cpp_generation_get_one_hint(tmp_path: Path) -> None:
    genmsg = (
        "CMake Error at build/demo/cmake/demo-genmsg.cmake:3 (message):\n  Could not find messages which\n"
        "  '/ws/devel/share/demo/msg/MoveAction.msg' depends on.\n\n  Cannot locate message [GoalID] in "
        f"package [actionlib_msgs] with paths\n  [['{tmp_path / 'nowhere'}']]\n"
    )
    hint = missing_definitions_hint(genmsg)
    assert hint.startswith("ninjemys: ") and "ros-actionlib-msgs" in hint and "\n" not in hint
    (tmp_path / "nowhere").mkdir()
    assert missing_definitions_hint(genmsg) == ""  # the files are there: the error is something else
    assert missing_definitions_hint("undeclared_name") == ""


@needs_toolchain
def test_a_dependency_without_its_cpp_side_leaves_the_python_side_built(tmp_path: Path) -> None:
    """A course package with a Python node and a C++ node on ros_control's controller_manager
    library, which this machine lacks (ninjemys provides controller_manager's messages for C++, not its
    library; Debian has none): the build succeeds, the Python node is ready, and the C++ target is
    named as not built, saying which package's C++ side is missing. (tf was the example until
    `make test` installed Debian's libtf-dev.)"""
    pkg = tmp_path / "src" / "aruco_follow"
    (pkg / "src").mkdir(parents=True)
    (pkg / "scripts").mkdir()
    (pkg / "package.xml").write_text(
        PACKAGE_XML.replace("cpp_chat", "aruco_follow").replace(
            "<depend>std_msgs</depend>",
            "<depend>std_msgs</depend>\n  <depend>controller_manager_msgs</depend>",
        )
    )
    (pkg / "CMakeLists.txt").write_text(
        "cmake_minimum_required(VERSION 3.0.2)\nproject(aruco_follow)\n"
        "find_package(catkin REQUIRED COMPONENTS roscpp rospy controller_manager_msgs)\ncatkin_package()\n"
        "include_directories(${catkin_INCLUDE_DIRS})\nadd_executable(follow_node src/follow.cpp)\n"
        "target_link_libraries(follow_node ${catkin_LIBRARIES})\n"
        "catkin_install_python(PROGRAMS scripts/follow.py DESTINATION ${CATKIN_PACKAGE_BIN_DESTINATION})\n"
    )
    (pkg / "src" / "follow.cpp").write_text(
        "#include <ros/ros.h>\n#include <controller_manager/controller_manager.h>\nint main() { return 0; }\n"
    )
    (pkg / "scripts" / "follow.py").write_text(
        "#!/usr/bin/env python3\nfrom fiducial_msgs.msg import Fiducial\n"
    )
    (pkg / "scripts" / "follow.py").chmod(0o755)
    # a second C++ package that has all it needs: built all the same
    plain = tmp_path / "src" / "plain_node"
    (plain / "src").mkdir(parents=True)
    (plain / "package.xml").write_text(PACKAGE_XML.replace("cpp_chat", "plain_node"))
    (plain / "CMakeLists.txt").write_text(
        "cmake_minimum_required(VERSION 3.0.2)\nproject(plain_node)\n"
        "find_package(catkin REQUIRED COMPONENTS roscpp)\ncatkin_package()\n"
        "include_directories(${catkin_INCLUDE_DIRS})\nadd_executable(plain src/plain.cpp)\n"
        "target_link_libraries(plain ${catkin_LIBRARIES})\n"
    )
    (plain / "src" / "plain.cpp").write_text(
        '#include <ros/ros.h>\nint main(int argc, char **argv) { ros::init(argc, argv, "plain"); return 0; }\n'
    )
    env = {k: v for k, v in os.environ.items() if k not in ("ROS_PACKAGE_PATH", "CMAKE_PREFIX_PATH")}
    env.pop("NINJEMYS_CATKIN_CPP", None)
    result = subprocess.run(
        [ninjemys_bin("catkin_make")],
        cwd=tmp_path,
        env=env,
        capture_output=True,
        text=True,
        timeout=600,
        check=False,
    )
    out = result.stdout + result.stderr
    if "C++ program(s) built by catkin's CMake: follow_node" in out:
        pytest.skip("controller_manager's C++ side is installed here")
    assert result.returncode == 0, out
    assert "aruco_follow: 1 C++ target(s) not built" in out
    assert "[the C++ side of 'controller_manager' is not installed" in out
    assert (tmp_path / "devel" / "lib" / "aruco_follow" / "follow.py").is_file()
    assert "plain_node: C++ program(s) built by catkin's CMake: plain" in out
    assert (tmp_path / "devel" / "lib" / "plain_node" / "plain").is_file()


def test_the_failing_package_is_told_from_cmakes_call_stack_or_the_compiler() -> None:
    stack = "CMake Error at /usr/share/catkin/cmake/catkinConfig.cmake:82 (find_package):\n"
    stack += "Call Stack (most recent call first):\n  aruco_follow/CMakeLists.txt:3 (find_package)\n"
    assert failing_package(stack, {"aruco_follow", "plain_node"}) == "aruco_follow"
    compiler = "/ws/build/ninjemys_cpp/src/plain_node/src/x.cpp:2:10: fatal error: a/b.h: No such file\n"
    assert failing_package(compiler, {"aruco_follow", "plain_node"}) == "plain_node"
    assert failing_package("something else", {"plain_node"}) is None


def test_which_failures_mean_a_missing_cpp_side() -> None:
    configure = 'CMake Error ...\n  Could not find a package configuration file provided by "nav_msgs" with\n'
    assert missing_cpp_dependency(configure + 'Invoking "cmake" failed') == ("nav_msgs", False)
    header = "node.cpp:2:10: fatal error: control_msgs/JointControllerState.h: No such file or directory\n"
    assert missing_cpp_dependency(header + 'Invoking "make -j2" failed') == ("control_msgs", True)
    own = "node.cpp:2:19: error: 'undeclared_name' was not declared in this scope\n"
    assert missing_cpp_dependency(own + 'Invoking "make -j2" failed') is None

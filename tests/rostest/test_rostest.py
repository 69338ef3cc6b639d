"""rostest as course and book packages use it: a ``.test`` file that starts a node and runs a
unittest-based test node (``rostest.rosrun``), ``find_package(rostest)`` + ``add_rostest`` in
CMakeLists.txt, an offline ``rosunit.unitrun`` test; JUnit XML where ROS 1 writes it, and the exit
status. The ``ros1`` test runs Debian's rostest on the same package and compares the report."""

from __future__ import annotations

import os
import re
import subprocess
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest

from ninjemys.rostest.junit import CaseResult, SuiteResult, read_xml, results_file, write_xml
from ninjemys.rostest.pyunit import restore_removed_aliases
from ninjemys.testing import CatkinWorkspace, ninjemys_bin

PACKAGE_XML = """<?xml version="1.0"?>
<package format="2">
  <name>probe_tests</name>
  <version>0.1.0</version>
  <description>rostest patterns</description>
  <maintainer email="t@example.com">t</maintainer>
  <license>BSD</license>
  <buildtool_depend>catkin</buildtool_depend>
  <depend>rospy</depend>
  <depend>std_msgs</depend>
  <test_depend>rostest</test_depend>
</package>
"""

CMAKE = """cmake_minimum_required(VERSION 3.0.2)
project(probe_tests)
find_package(catkin REQUIRED COMPONENTS rospy std_msgs)
catkin_package()
if(CATKIN_ENABLE_TESTING)
  find_package(rostest REQUIRED)
  add_rostest(test/talker.test)
  add_rostest(test/failing.test)
  add_rostest(test/broken.test)
endif()
"""

TALKER = """#!/usr/bin/env python3
# Publishes "hello world N" on chatter until shut down.
import rospy
from std_msgs.msg import String

rospy.init_node("talker")
pub = rospy.Publisher("chatter", String, queue_size=10)
rate = rospy.Rate(20)
n = 0
while not rospy.is_shutdown():
    pub.publish(String(data="hello world %d" % n))
    n += 1
    rate.sleep()
"""

#: a test node as the books write it: a TestCase with old unittest names, rostest.rosrun at the end
HEARS = """#!/usr/bin/env python3
import sys
import time
import unittest

import rospy
import rostest
from std_msgs.msg import String


class TestTalker(unittest.TestCase):
    def test_hears_hello(self):
        heard = []
        rospy.init_node("test_talker")
        rospy.Subscriber("chatter", String, lambda m: heard.append(m.data))
        deadline = time.time() + 20.0
        while not heard and time.time() < deadline:
            time.sleep(0.05)
        self.assert_(heard and heard[0].startswith("hello world"))

    def test_param_from_test_file(self):
        self.assertEquals(rospy.get_param("~greeting"), "hi")


if __name__ == "__main__":
    rostest.rosrun("probe_tests", "talker_test", TestTalker, sys.argv)
"""

FAILS = """#!/usr/bin/env python3
import unittest

import rostest


class Arithmetic(unittest.TestCase):
    def test_right(self):
        self.assertEqual(1 + 1, 2)

    def test_wrong(self):
        self.assertEqual(1 + 1, 3)


if __name__ == "__main__":
    rostest.rosrun("probe_tests", "arith", Arithmetic)
"""

TALKER_TEST = """<launch>
  <node name="talker" pkg="probe_tests" type="talker.py"/>
  <test test-name="talker_test" pkg="probe_tests" type="test_hears.py" time-limit="60.0">
    <param name="greeting" value="hi"/>
  </test>
</launch>
"""

# a test file committed without chmod +x, and a test of a package that is not there (course repositories
# do both): those tests fail to run, the others run (CarND-Capstone's dbw_sim.test)
UNRUNNABLE_TEST = """<launch>
  <test test-name="arith" pkg="probe_tests" type="test_fails.py"/>
  <test test-name="plain" pkg="probe_tests" type="test_plain.py"/>
  <test test-name="elsewhere" pkg="no_such_probe_pkg" type="test_x.py"/>
</launch>
"""

FAILING_TEST = """<launch>
  <test test-name="arith" pkg="probe_tests" type="test_fails.py"/>
</launch>
"""

SLOW_TEST = """<launch>
  <test test-name="sleeper" pkg="probe_tests" type="sleeper.py" time-limit="2.0"/>
</launch>
"""

SLEEPER = "#!/usr/bin/env python3\nimport time\ntime.sleep(60)\n"

#: rostest's stock hztest on the talker (20 Hz), and one that expects a rate it cannot have
HZ_TEST = """<launch>
  <node name="talker" pkg="probe_tests" type="talker.py"/>
  <test test-name="talker_hz" pkg="rostest" type="hztest" name="hz">
    <param name="topic" value="chatter"/>
    <param name="hz" value="20.0"/>
    <param name="hzerror" value="6.0"/>
    <param name="test_duration" value="2.0"/>
  </test>
  <test test-name="talker_too_slow" pkg="rostest" type="hztest" name="hz_fast">
    <param name="topic" value="chatter"/>
    <param name="hz" value="100.0"/>
    <param name="hzerror" value="10.0"/>
    <param name="test_duration" value="2.0"/>
  </test>
</launch>
"""

#: rostest's publishtest: chatter comes, /nobody stays silent (negative); /silent never comes
PUBLISH_TEST = """<launch>
  <node name="talker" pkg="probe_tests" type="talker.py"/>
  <test test-name="chatter_published" pkg="rostest" type="publishtest" name="publish">
    <rosparam>
topics:
  - name: /chatter
    timeout: 30
  - name: /nobody
    timeout: 2
    negative: true
    </rosparam>
  </test>
  <test test-name="silent_published" pkg="rostest" type="publishtest" name="publish_silent">
    <rosparam>
topics:
  - name: /silent
    timeout: 2
    </rosparam>
  </test>
</launch>
"""

#: rostest's paramtest: a parameter set by the file (right value, wrong value) and one never set
PARAM_TEST = """<launch>
  <param name="robot_name" value="probe"/>
  <test test-name="param_set" pkg="rostest" type="paramtest" name="param_set">
    <param name="param_name_target" value="/robot_name"/>
    <param name="param_value_expected" value="probe"/>
    <param name="wait_time" value="5"/>
  </test>
  <test test-name="param_wrong" pkg="rostest" type="paramtest" name="param_wrong">
    <param name="param_name_target" value="/robot_name"/>
    <param name="param_value_expected" value="other"/>
    <param name="wait_time" value="5"/>
  </test>
  <test test-name="param_missing" pkg="rostest" type="paramtest" name="param_missing">
    <param name="param_name_target" value="/nowhere"/>
    <param name="wait_time" value="1"/>
  </test>
</launch>
"""

#: rostest's advertisetest: the talker's topic and logger service (with their types), and a topic
#: that is never advertised beside one that must not be
ADVERTISE_TEST = """<launch>
  <node name="talker" pkg="probe_tests" type="talker.py"/>
  <test test-name="advertised" pkg="rostest" type="advertisetest" name="advertise">
    <rosparam>
topics:
  - name: /chatter
    type: std_msgs/String
    timeout: 30
services:
  - name: /talker/get_loggers
    type: roscpp/GetLoggers
    timeout: 30
    </rosparam>
  </test>
  <test test-name="not_advertised" pkg="rostest" type="advertisetest" name="advertise_missing">
    <rosparam>
topics:
  - name: /missing
    timeout: 2
  - name: /nobody
    timeout: 2
    negative: true
    </rosparam>
  </test>
</launch>
"""


def _workspace(root: Path) -> CatkinWorkspace:
    ws = CatkinWorkspace(root)
    scripts = {"scripts/talker.py": TALKER, "test/test_hears.py": HEARS, "test/test_fails.py": FAILS}
    scripts["test/sleeper.py"] = SLEEPER
    ws.package(
        "probe_tests",
        {
            "package.xml": PACKAGE_XML,
            "CMakeLists.txt": CMAKE,
            **scripts,
            "test/talker.test": TALKER_TEST,
            "test/failing.test": FAILING_TEST,
            "test/slow.test": SLOW_TEST,
            "test/hz.test": HZ_TEST,
            "test/publish.test": PUBLISH_TEST,
            "test/param.test": PARAM_TEST,
            "test/advertise.test": ADVERTISE_TEST,
            "test/broken.test": "<launch><test test-name=",
            "test/unrunnable.test": UNRUNNABLE_TEST,
            "test/test_plain.py": FAILS,  # not executable
        },
        executables=list(scripts),
    )
    return ws


def _env(ws: Path) -> dict[str, str]:
    return CatkinWorkspace(ws).env()


@pytest.fixture(scope="module")
def workspace(tmp_path_factory: pytest.TempPathFactory) -> Path:
    ws = _workspace(tmp_path_factory.mktemp("rostest_ws"))
    made = ws.catkin_make(timeout=300)
    assert made.returncode == 0, made.stdout + made.stderr
    return ws.root


def _rostest(ws: Path, *args: str, timeout: float = 180) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [ninjemys_bin("rostest"), *args],
        cwd=ws,
        env=_env(ws),
        capture_output=True,
        text=True,
        timeout=timeout,
        check=False,
    )


def test_a_passing_test_file_runs_its_node_and_test_node(workspace: Path) -> None:
    result = _rostest(workspace, "probe_tests", "talker.test")
    out = result.stdout
    assert result.returncode == 0, out + result.stderr
    assert "[Testcase: testtalker_test] ... ok" in out
    assert "[probe_tests.rosunit-talker_test/test_hears_hello][passed]" in out
    assert "[probe_tests.rosunit-talker_test/test_param_from_test_file][passed]" in out
    assert re.search(r"SUMMARY\n.* \* RESULT: SUCCESS.*\n \* TESTS: 2\n \* ERRORS: 0\n \* FAILURES: 0", out)
    results = workspace / "ros_home" / "test_results" / "probe_tests"
    # rostest's own case per <test>, as ROS 1 writes the combined file; the node's cases in its own
    combined = read_xml(results / "rostest-test_talker.xml")
    assert [(c.classname, c.name) for c in combined.cases] == [("rostest.runner.RosTest", "testtalker_test")]
    assert combined.ok
    assert read_xml(results / "rosunit-talker_test.xml").ok
    # the test node's own output went to its log, not the console
    assert "Outputting test results to" in out and "Ran 2 tests" not in out


def test_tests_that_cannot_run_fail_and_the_others_run(workspace: Path) -> None:
    result = _rostest(workspace, "probe_tests", "unrunnable.test")
    out = re.sub(r"\x1b\[[0-9;]*m", "", result.stdout)
    assert result.returncode == 1, out + result.stderr
    assert "[Testcase: testarith] ... ok" in out
    assert "FAILURE: Test node [probe_tests/test_plain.py] does not exist or is not executable" in out
    assert (
        "FAILURE: Package [no_such_probe_pkg] for test node [no_such_probe_pkg/test_x.py] does not exist"
        in out
    )
    assert "ERROR: The following tests failed to run:\n * testelsewhere\n * testplain\n" in out
    results = workspace / "ros_home" / "test_results" / "probe_tests"
    combined = read_xml(results / "rostest-test_unrunnable.xml")
    # rostest's own case per test: the two that could not run fail (catkin_test_results counts them)
    assert [(c.name, c.passed) for c in combined.cases] == [
        ("testarith", True),
        ("testelsewhere", False),
        ("testplain", False),
    ]


def test_a_failing_case_fails_the_run_and_is_named(workspace: Path) -> None:
    """As in ROS 1: the test node ran and reported (``[Testcase: ...] ... ok``), one of its cases
    failed: the FAILURE block with the assertion's message, and exit status 2."""
    result = _rostest(workspace, str(workspace / "src" / "probe_tests" / "test" / "failing.test"))
    out = result.stdout
    assert result.returncode == 2, out + result.stderr
    assert "[Testcase: testarith] ... ok" in out
    assert "[probe_tests.rosunit-arith/test_right][passed]" in out
    head = "[probe_tests.rosunit-arith/test_wrong][FAILURE]"
    assert f"{head}{'-' * (80 - len(head))}\n2 != 3\n" in out
    assert "\x1b[1;31m * FAILURES: 1\x1b[0m" in out


def test_a_test_over_its_time_limit_fails(workspace: Path) -> None:
    result = _rostest(workspace, "probe_tests", "slow.test", timeout=60)
    assert result.returncode == 1
    assert "[Testcase: testsleeper] ... ERROR!" in result.stdout
    assert "max time [2.0s] allotted for test [sleeper] of type [probe_tests/sleeper.py]" in result.stdout
    assert "\x1b[1;31m * ERRORS: 1\x1b[0m" in result.stdout


def test_hztest_checks_a_topics_rate(workspace: Path) -> None:
    result = _rostest(workspace, "probe_tests", "hz.test")
    out = result.stdout
    assert result.returncode == 2, out + result.stderr
    assert "[probe_tests.rosunit-talker_hz/test_hz][passed]" in out
    assert "[probe_tests.rosunit-talker_too_slow/test_hz][FAILURE]" in out
    assert "exceeded minimum (90.000Hz)" in out


def test_publishtest_waits_for_messages_on_each_topic(workspace: Path) -> None:
    result = _rostest(workspace, "probe_tests", "publish.test")
    out = result.stdout
    assert result.returncode == 2, out + result.stderr
    assert "[probe_tests.rosunit-chatter_published/test_publish][passed]" in out
    assert "[probe_tests.rosunit-silent_published/test_publish][FAILURE]" in out
    assert "Topic [/silent] is not published" in out


def test_paramtest_checks_a_parameter_and_its_value(workspace: Path) -> None:
    result = _rostest(workspace, "probe_tests", "param.test")
    out = result.stdout
    assert result.returncode == 2, out + result.stderr
    assert "[probe_tests.rosunit-param_set/test_param][passed]" in out
    assert "[probe_tests.rosunit-param_wrong/test_param][FAILURE]" in out
    assert "'other' != 'probe'" in out
    assert "[probe_tests.rosunit-param_missing/test_param][FAILURE]" in out
    assert "unexpectedly None" in out


def test_advertisetest_checks_topics_services_and_types(workspace: Path) -> None:
    result = _rostest(workspace, "probe_tests", "advertise.test")
    out = result.stdout
    assert result.returncode == 2, out + result.stderr
    assert "[probe_tests.rosunit-advertised/test_advertise_topics][passed]" in out
    assert "[probe_tests.rosunit-advertised/test_advertise_services][passed]" in out
    assert "[probe_tests.rosunit-not_advertised/test_advertise_services][passed]" in out  # none listed
    assert "[probe_tests.rosunit-not_advertised/test_advertise_topics][FAILURE]" in out
    assert "Topic [/missing] is not advertised" in out


def test_find_package_rostest_is_known_to_catkin_make(workspace: Path) -> None:
    listed = subprocess.run(
        [ninjemys_bin("rospack"), "find", "rostest"],
        env=_env(workspace),
        capture_output=True,
        text=True,
        check=False,
    )
    assert listed.returncode == 0 and listed.stdout.strip().endswith("rostest"), listed.stderr


def test_rosunit_unitrun_writes_xml_and_exits_1_on_failure(tmp_path: Path) -> None:
    script = tmp_path / "offline.py"
    script.write_text(
        "import unittest, rosunit\n"
        "class T(unittest.TestCase):\n"
        "    def test_ok(self):\n        self.failUnlessEqual(2, 2)\n"
        "    def test_bad(self):\n        self.assertTrue(False, 'deliberately')\n"
        "rosunit.unitrun('probe_tests', 'offline', T)\n"
    )
    env = dict(os.environ, ROS_HOME=str(tmp_path / "home"))
    env.pop("ROS_TEST_RESULTS_DIR", None)
    result = subprocess.run(
        [sys.executable, str(script)], env=env, capture_output=True, text=True, timeout=60, check=False
    )
    assert result.returncode == 1, result.stdout + result.stderr
    assert (
        "[Testcase: test_bad] ... FAILURE!" in result.stdout and " * FAILURES: 1 [test_bad]" in result.stdout
    )
    suite = ET.parse(tmp_path / "home" / "test_results" / "probe_tests" / "rosunit-offline.xml").getroot()
    assert (suite.get("tests"), suite.get("failures"), suite.get("errors")) == ("2", "1", "0")


def test_results_round_trip_and_name_cleaning(tmp_path: Path) -> None:
    env = {"ROS_HOME": str(tmp_path)}
    path = results_file("pkg", "my test/one", env=env)
    assert path == tmp_path / "test_results" / "pkg" / "rosunit-my_test_one.xml"
    write_xml(
        path,
        SuiteResult("s", [CaseResult("C", "a"), CaseResult("C", "b", failure="boom\nAssertionError: x")]),
    )
    back = read_xml(path)
    assert [c.name for c in back.cases] == ["a", "b"] and back.cases[1].failure is not None and not back.ok


def test_old_unittest_names_are_there() -> None:
    import unittest

    restore_removed_aliases()
    assert unittest.TestCase.assertEquals is not None and unittest.TestCase.assert_ is not None


def _report_lines(text: str) -> list[str]:
    """The [ROSTEST] block's result lines and the SUMMARY, colours and paths aside."""
    lines = [re.sub(r"\x1b\[[0-9;]*m", "", line) for line in text.splitlines()]
    keep = [ln for ln in lines if ln.startswith(("[probe_tests.", " * ", "[Testcase:"))]
    return keep


@pytest.mark.ros1
@pytest.mark.skipif(
    not Path("/usr/bin/rostest").exists(), reason="Debian's rostest (python3-rostest) not installed"
)
@pytest.mark.parametrize(
    ("test_file", "code"),
    [
        ("talker.test", 0),
        ("failing.test", 2),
        ("slow.test", 1),
        ("unrunnable.test", 1),
        ("hz.test", 2),
        ("publish.test", 2),
        ("param.test", 2),
        ("advertise.test", 2),
    ],
)
def test_same_report_as_debians_rostest(workspace: Path, tmp_path: Path, test_file: str, code: int) -> None:
    theirs = _workspace(tmp_path / "debian").root
    env = {
        "PATH": "/usr/bin:/bin",
        "HOME": str(tmp_path / "home"),
        "LANG": "C.UTF-8",
        "ROS_PACKAGE_PATH": str(theirs / "src"),
        "ROS_HOSTNAME": "localhost",
    }
    debian = subprocess.run(
        ["/usr/bin/rostest", "probe_tests", test_file],
        cwd=theirs,
        env=env,
        capture_output=True,
        text=True,
        timeout=180,
        check=False,
    )
    ours = _rostest(workspace, "probe_tests", test_file)
    assert (debian.returncode, ours.returncode) == (code, code), debian.stdout + debian.stderr
    assert _report_lines(ours.stdout) == _report_lines(debian.stdout)
    # the combined file: rostest's own case per <test>, passing or not, as Debian's
    name = f"rostest-test_{test_file.split('.')[0]}.xml"
    theirs_xml = read_xml(tmp_path / "home" / ".ros" / "test_results" / "probe_tests" / name)
    ours_xml = read_xml(workspace / "ros_home" / "test_results" / "probe_tests" / name)
    assert [(c.classname, c.name, c.passed) for c in ours_xml.cases] == [
        (c.classname, c.name, c.passed) for c in theirs_xml.cases
    ]


@pytest.fixture(scope="module")
def run_tests(workspace: Path) -> tuple[subprocess.CompletedProcess[str], Path]:
    """``catkin_make run_tests`` once for the module (three rostests): its output and results dir."""
    made = CatkinWorkspace(workspace).catkin_make("run_tests", timeout=300)
    return made, workspace / "build" / "test_results"


def test_catkin_make_run_tests_runs_the_add_rostest_files(run_tests) -> None:
    """Results where catkin's add_rostest puts them: build/test_results/<pkg>/rostest-<file>.xml."""
    made, results = run_tests
    assert made.returncode == 0, made.stdout + made.stderr
    assert "-- run_tests_probe_tests_rostest_test_talker.test" in made.stdout
    assert "[probe_tests.rosunit-talker_test/test_hears_hello][passed]" in made.stdout
    assert read_xml(results / "probe_tests" / "rostest-test_talker.xml").ok
    # the test node ran and wrote its results: rostest's own case passes, the node's failure is in
    # its rosunit- file (as ROS 1 writes them), so it is counted once
    assert read_xml(results / "probe_tests" / "rostest-test_failing.xml").ok
    failing = read_xml(results / "probe_tests" / "rosunit-arith.xml")
    assert len(failing.cases) == 2 and not failing.ok
    # broken.test writes no result: a MISSING- failure file stands for it, as catkin's run_tests.py
    missing = results / "probe_tests" / "MISSING-rostest-test_broken.xml"
    assert not read_xml(missing).ok
    assert f"Cannot find results, writing failure results to '{missing}'" in made.stderr


@pytest.mark.ros1
@pytest.mark.skipif(
    not Path("/usr/bin/catkin_test_results").exists(), reason="Debian's catkin_test_results not installed"
)
def test_debians_catkin_test_results_counts_them(run_tests) -> None:
    """``catkin_make run_tests && catkin_test_results``, the CI idiom: the failures are counted."""
    _made, results = run_tests
    summary = subprocess.run(
        ["/usr/bin/catkin_test_results", str(results)],
        env={"PATH": "/usr/bin:/bin", "LANG": "C.UTF-8"},
        capture_output=True,
        text=True,
        timeout=60,
        check=False,
    )
    assert summary.returncode == 1, summary.stdout + summary.stderr
    # rostest's combined files, the test nodes' own rosunit- files beside them (as ROS 1 writes them
    # with --results-base-dir), and the MISSING- stand-in for broken.test
    assert "probe_tests/MISSING-rostest-test_broken.xml: 1 tests, 0 errors, 1 failures" in summary.stdout
    assert "probe_tests/rosunit-arith.xml: 2 tests, 0 errors, 1 failures" in summary.stdout
    # talker: rostest's case + the node's 2; failing: 1 + 2 (one failure); broken: the MISSING- one
    assert "Summary: 7 tests, 0 errors, 2 failures, 0 skipped" in summary.stdout, summary.stdout


def test_results_filename_is_a_name_in_the_results_dir(workspace: Path, tmp_path: Path) -> None:
    """``--results-filename`` names the file inside ``--results-base-dir``/<pkg>, as rostest_main does."""
    ran = _rostest(
        workspace,
        "--results-filename",
        "chosen.name.xml",
        "--results-base-dir",
        str(tmp_path / "results"),
        "probe_tests",
        "failing.test",
    )
    assert ran.returncode == 2, ran.stdout + ran.stderr
    written = tmp_path / "results" / "probe_tests" / "rostest-chosen.name.xml"
    assert f"[ROSUNIT] Outputting test results to {written}" in ran.stdout
    assert [c.name for c in read_xml(written).cases] == ["testarith"]
    assert len(read_xml(tmp_path / "results" / "probe_tests" / "rosunit-arith.xml").cases) == 2

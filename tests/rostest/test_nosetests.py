"""``catkin_add_nosetests``: ``catkin_make run_tests`` collects and runs them by nose's rules and writes
nose's xunit file where catkin 0.8 puts it; Debian's catkin_make (with Debian's nose) is the reference."""

from __future__ import annotations

import shutil
import subprocess
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest

from ninjemys.testing import CatkinWorkspace

PACKAGE_XML = """<?xml version="1.0"?>
<package format="2">
  <name>nosy</name>
  <version>0.1.0</version>
  <description>a package with nose tests</description>
  <maintainer email="me@example.com">me</maintainer>
  <license>BSD</license>
  <buildtool_depend>catkin</buildtool_depend>
  <test_depend>rosunit</test_depend>
</package>
"""

CMAKE = """cmake_minimum_required(VERSION 3.0.2)
project(nosy)
find_package(catkin REQUIRED)
catkin_python_setup()
catkin_package()
if(CATKIN_ENABLE_TESTING)
  catkin_add_nosetests(test)
  catkin_add_nosetests(${PROJECT_SOURCE_DIR}/test/test_single.py)
  catkin_add_nosetests(other/check_more.py WORKING_DIRECTORY ${PROJECT_SOURCE_DIR}/other)
endif()
"""

SETUP = """from setuptools import setup
from catkin_pkg.python_setup import generate_distutils_setup
setup(**generate_distutils_setup(packages=["nosy"], package_dir={"": "src"}))
"""

MATH = """import unittest
import nosy

calls = []

def setup_module():
    calls.append("module")

class TestAdd(unittest.TestCase):
    def test_add(self):
        self.assertEqual(nosy.add(1, 2), 3)
    def test_wrong(self):
        self.assertEqual(nosy.add(1, 1), 3)
    @unittest.skip("not today")
    def test_skipped(self):
        pass
    def helper(self):
        raise AssertionError("not a test")

class TestPlain(object):
    def setup(self):
        self.value = 2
    def test_uses_setup(self):
        assert self.value == 2 and calls == ["module"]

class NotTested(object):
    def test_never(self):
        raise AssertionError("the class name does not match")

def test_function():
    assert nosy.add(2, 2) == 4

def test_error():
    raise RuntimeError("boom")

def test_generated():
    for n in (1, 2):
        yield check_even, n

def check_even(n):
    assert n % 2 == 0

def helper():
    raise AssertionError("not collected")

def test_opted_out():
    raise AssertionError("__test__ = False")
test_opted_out.__test__ = False
"""

SINGLE = """def test_one():
    pass
"""

# executable: nose (without --exe) skips it in a directory
EXECUTABLE = """#!/usr/bin/env python3
def test_skipped_as_executable():
    raise AssertionError("executable files are not collected")
"""

BROKEN = """import no_such_module_anywhere
def test_never_runs():
    pass
"""

PKG_TESTS = """from . import helper_values

def test_relative_import():
    assert helper_values.VALUE == 3

class TestWithClassFixture:
    @classmethod
    def setup_class(cls):
        cls.ready = True
    def test_ready(self):
        assert self.ready
"""

MORE = """import os
def test_cwd():
    assert os.path.basename(os.getcwd()) == "other"
"""


def _workspace(root: Path) -> CatkinWorkspace:
    ws = CatkinWorkspace(root)
    ws.package(
        "nosy",
        {
            "package.xml": PACKAGE_XML,
            "CMakeLists.txt": CMAKE,
            "setup.py": SETUP,
            "src/nosy/__init__.py": "def add(a, b):\n    return a + b\n",
            "test/test_math.py": MATH,
            "test/test_single.py": SINGLE,
            "test/test_exec.py": EXECUTABLE,
            "test/test_broken.py": BROKEN,
            "test/unit_tests/test_deeper.py": SINGLE,  # a directory matching testMatch: searched
            "test/sub/test_other.py": BROKEN,  # one that does not match: not searched
            "test/helpers/test_hidden.py": BROKEN,  # neither a package nor a matching name: not searched
            "other/check_more.py": MORE,
            # a package of tests: module names through the package, relative imports, setup_class
            "test/pkg_tests/__init__.py": "",
            "test/pkg_tests/helper_values.py": "VALUE = 3\n",
            "test/pkg_tests/test_pkg.py": PKG_TESTS,
        },
        executables=["test/test_exec.py"],
    )
    return ws


def _cases(path: Path) -> tuple[dict[str, str], list[tuple[str, str, str]]]:
    """The suite's counts and each case as (classname, name, outcome)."""
    root = ET.parse(path).getroot()
    counts = {k: root.get(k, "") for k in ("name", "tests", "errors", "failures", "skip")}
    cases = []
    for case in root.iter("testcase"):
        outcome = next((child.tag for child in case if child.tag in ("failure", "error", "skipped")), "ok")
        cases.append((case.get("classname", ""), case.get("name", ""), outcome))
    return counts, sorted(cases)


def _results(results: Path) -> dict[str, tuple[dict[str, str], list[tuple[str, str, str]]]]:
    return {str(p.relative_to(results)): _cases(p) for p in sorted(results.rglob("*.xml"))}


def test_run_tests_collects_by_noses_rules(tmp_path: Path) -> None:
    ws = _workspace(tmp_path)
    made = ws.catkin_make("run_tests")
    assert made.returncode == 0, made.stdout + made.stderr
    results = _results(tmp_path / "build" / "test_results")
    assert set(results) == {
        "nosy/nosetests-test.xml",
        "nosy/nosetests-test.test_single.py.xml",
        "nosy/nosetests-other.check_more.py.xml",
    }
    counts, cases = results["nosy/nosetests-test.xml"]
    assert counts == {"name": "nosetests", "tests": "13", "errors": "2", "failures": "2", "skip": "1"}
    assert cases == [
        ("nose.failure.Failure", "runTest", "error"),  # test_broken.py does not import
        ("pkg_tests.test_pkg", "test_relative_import", "ok"),
        ("pkg_tests.test_pkg.TestWithClassFixture", "test_ready", "ok"),
        ("test_deeper", "test_one", "ok"),
        ("test_math", "test_error", "error"),
        ("test_math", "test_function", "ok"),
        ("test_math", "test_generated(1,)", "failure"),
        ("test_math", "test_generated(2,)", "ok"),
        ("test_math.TestAdd", "test_add", "ok"),
        ("test_math.TestAdd", "test_skipped", "skipped"),
        ("test_math.TestAdd", "test_wrong", "failure"),
        ("test_math.TestPlain", "test_uses_setup", "ok"),
        ("test_single", "test_one", "ok"),
    ]
    assert results["nosy/nosetests-other.check_more.py.xml"][1] == [("check_more", "test_cwd", "ok")]
    assert "-- run_tests_nosy_nosetests_test\n" in made.stdout
    assert "FAIL: test_wrong" in made.stderr and "No module named 'no_such_module_anywhere'" in made.stderr


def test_old_results_are_removed_and_results_dir_can_be_chosen(tmp_path: Path) -> None:
    ws = _workspace(tmp_path / "ws")
    stale = tmp_path / "chosen" / "nosy" / "nosetests-gone.xml"
    stale.parent.mkdir(parents=True)
    stale.write_text("<testsuite/>")
    made = ws.catkin_make("run_tests", f"-DCATKIN_TEST_RESULTS_DIR={tmp_path / 'chosen'}")
    assert made.returncode == 0, made.stdout + made.stderr
    assert f"- removing '{stale}'" in made.stdout and not stale.exists()
    assert (tmp_path / "chosen" / "nosy" / "nosetests-test.xml").is_file()
    assert not (tmp_path / "ws" / "build" / "test_results").exists()


def _missing_path(ws: CatkinWorkspace) -> None:
    cmake = ws.root / "src" / "nosy" / "CMakeLists.txt"
    cmake.write_text(cmake.read_text().replace("catkin_add_nosetests(test)", "catkin_add_nosetests(tests)"))


MISSING_PATH = (
    "CMake Error at /usr/share/catkin/cmake/test/nosetests.cmake:54 (message):\n"
    "  Can't find nosetests path 'tests'\nCall Stack (most recent call first):\n"
    "  nosy/CMakeLists.txt:7 (catkin_add_nosetests)"
)


def test_a_missing_path_stops_the_build_as_catkins_configure_does(tmp_path: Path) -> None:
    ws = _workspace(tmp_path)
    _missing_path(ws)
    made = ws.catkin_make()
    assert made.returncode == 1
    assert MISSING_PATH in made.stderr
    assert not (tmp_path / "devel").exists()
    # with testing off, catkin registers no tests: the build passes and run_tests runs none
    made = ws.catkin_make("run_tests", "-DCATKIN_ENABLE_TESTING=OFF")
    assert made.returncode == 0, made.stdout + made.stderr
    assert not (tmp_path / "build" / "test_results" / "nosy").exists()


@pytest.mark.ros1
@pytest.mark.skipif(
    not Path("/usr/bin/catkin_make").exists()
    or not Path("/usr/bin/nosetests3").exists()
    or not shutil.which("cmake"),
    reason="Debian's catkin, nose or cmake not installed",
)
def test_same_results_as_debians_catkin_make(tmp_path: Path) -> None:
    """The same result files, counts and cases as Debian's catkin_make run_tests (with nose 1.3)."""
    theirs, ours = _workspace(tmp_path / "debian"), _workspace(tmp_path / "ours")
    env = {"PATH": "/usr/bin:/bin", "HOME": str(tmp_path), "LANG": "C.UTF-8"}
    debian = subprocess.run(
        ["/usr/bin/catkin_make", "run_tests", f"-DCATKIN_TEST_RESULTS_DIR={tmp_path / 'debian_results'}"],
        cwd=theirs.root,
        env=env,
        capture_output=True,
        text=True,
        timeout=600,
        check=False,
    )
    assert debian.returncode == 0, debian.stdout + debian.stderr
    made = ours.catkin_make("run_tests", f"-DCATKIN_TEST_RESULTS_DIR={tmp_path / 'our_results'}")
    assert made.returncode == 0, made.stdout + made.stderr
    expected = _results(tmp_path / "debian_results")
    assert expected  # Debian ran them
    assert _results(tmp_path / "our_results") == expected
    summary = [
        subprocess.run(
            ["/usr/bin/catkin_test_results", str(tmp_path / d)],
            env=env,
            capture_output=True,
            text=True,
            timeout=60,
            check=False,
        )
        for d in ("debian_results", "our_results")
    ]
    assert summary[0].returncode == summary[1].returncode == 1
    assert summary[0].stdout.splitlines()[-1] == summary[1].stdout.splitlines()[-1]
    # a path that does not exist: both stop at configure with catkin's message
    _missing_path(theirs)
    shutil.rmtree(theirs.root / "build")
    debian = subprocess.run(
        ["/usr/bin/catkin_make"], cwd=theirs.root, env=env, capture_output=True, text=True, timeout=600
    )
    assert debian.returncode != 0 and MISSING_PATH in debian.stderr, debian.stdout + debian.stderr

"""What course launch files meet in ROS 1's roslaunch, side by side with Debian's.

- A node reads roslaunch's own stdin: ``roslaunch turtlebot3_teleop turtlebot3_teleop_key.launch`` is
  how the TurtleBot3 book drives the robot, and turtlebot3_example's client asks for its goal with
  ``input()``. ROS 1 hands the nodes roslaunch's stdin; a node given /dev/null cannot be driven.
- A launch-prefix naming a program that is not installed (a course's ``launch-prefix="gnome-terminal
  --command"`` on a machine without GNOME) stops the launch with ROS 1's "bad launch-prefix"
  message and exit code 1, before any later node starts; so does a node file without its ``#!``
  line (ROS 1: "you may be missing a '#!' declaration").
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

from ninjemys import testing

OURS = str(Path(sys.executable).parent / "roslaunch")
DEBIAN = "/usr/bin/roslaunch"

READER = """#!/usr/bin/env python3
import sys

line = sys.stdin.readline().strip()
print(f"read from the terminal: [{line}]", flush=True)
"""

PACKAGE_XML = (
    '<package format="2"><name>keys_pkg</name><version>0.0.1</version><description>d</description>'
    '<maintainer email="dev@example.com">d</maintainer><license>BSD</license>'
    "<buildtool_depend>catkin</buildtool_depend></package>"
)

READ_LAUNCH = """<launch>
  <node pkg="keys_pkg" type="read_key.py" name="keys" output="screen" required="true"/>
</launch>
"""

PREFIX_LAUNCH = """<launch>
  <node pkg="keys_pkg" type="read_key.py" name="first" output="screen"
        launch-prefix="no-such-terminal-program --command"/>
  <node pkg="keys_pkg" type="read_key.py" name="second" output="screen"/>
</launch>
"""

#: a node file without its "#!" line (a student's chmod +x'ed script): exec refuses it (ENOEXEC)
NO_SHEBANG_LAUNCH = """<launch>
  <node pkg="keys_pkg" type="plain_node" name="plain" output="screen"/>
  <node pkg="keys_pkg" type="read_key.py" name="second" output="screen"/>
</launch>
"""
NO_SHEBANG_LINE = "If it is a script, you may be missing a '#!' declaration at the top."

BAD_PREFIX_LINES = (
    "Roslaunch got a 'No such file or directory' error while attempting to run:",
    "no-such-terminal-program --command ",
    "Please make sure that all the executables in this command exist and have\n"
    "executable permission. This is often caused by a bad launch-prefix.",
)


def _package(tmp: Path) -> Path:
    pkg = tmp / "src" / "keys_pkg"
    pkg.mkdir(parents=True)
    (pkg / "package.xml").write_text(PACKAGE_XML)
    node = pkg / "read_key.py"
    node.write_text(READER)
    node.chmod(0o755)
    plain = pkg / "plain_node"
    plain.write_text("echo started without a shebang\n")
    plain.chmod(0o755)
    return tmp / "src"


def _ours_env(tmp: Path, src: Path) -> dict[str, str]:
    return dict(os.environ, ROS_HOME=str(tmp / "ours"), ROS_PACKAGE_PATH=str(src), ROS_HOSTNAME="localhost")


def _debian_env(tmp: Path, src: Path) -> dict[str, str]:
    return {
        "PATH": "/usr/bin:/bin",
        "HOME": str(tmp),
        "ROS_HOME": str(tmp / "debian"),
        "ROS_PACKAGE_PATH": f"{src}:/usr/share",
        "ROS_HOSTNAME": "localhost",
        "LANG": "C.UTF-8",
    }


def _roslaunch(command: str, launch: Path, env: dict[str, str], stdin_text: str) -> tuple[int, str]:
    """Run roslaunch on its own master with ``stdin_text`` on its stdin until it exits by itself."""
    port = testing.free_port()
    proc = subprocess.Popen(
        [command, "-p", str(port), str(launch)],
        env=dict(env, ROS_MASTER_URI=f"http://localhost:{port}/"),
        stdin=subprocess.PIPE,
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
        start_new_session=True,
    )
    try:
        out = proc.communicate(stdin_text, timeout=90)[0]
    except subprocess.TimeoutExpired:
        testing.kill_tree(proc)
        out = proc.communicate()[0]
        pytest.fail(f"{command} did not end by itself:\n{out}")
    for code in ("\x1b[31m", "\x1b[0m", "\x1b[1m"):
        out = out.replace(code, "")
    return proc.returncode, out


def test_a_launched_node_reads_roslaunchs_stdin(tmp_path: Path) -> None:
    src = _package(tmp_path)
    (tmp_path / "read.launch").write_text(READ_LAUNCH)
    code, out = _roslaunch(OURS, tmp_path / "read.launch", _ours_env(tmp_path, src), "forward\n")
    assert "read from the terminal: [forward]" in out, out
    assert "REQUIRED process [keys" in out, out
    assert code == 0, out


def test_a_missing_launch_prefix_program_stops_the_launch(tmp_path: Path) -> None:
    src = _package(tmp_path)
    (tmp_path / "prefix.launch").write_text(PREFIX_LAUNCH)
    code, out = _roslaunch(OURS, tmp_path / "prefix.launch", _ours_env(tmp_path, src), "")
    assert code == 1, out
    for line in BAD_PREFIX_LINES:
        assert line in out, out
    assert "process[second" not in out, out
    assert "process[first" not in out, out


def test_a_node_file_without_shebang_stops_the_launch(tmp_path: Path) -> None:
    src = _package(tmp_path)
    (tmp_path / "plain.launch").write_text(NO_SHEBANG_LAUNCH)
    code, out = _roslaunch(OURS, tmp_path / "plain.launch", _ours_env(tmp_path, src), "")
    assert code == 1, out
    assert "Unable to launch [plain" in out and NO_SHEBANG_LINE in out, out
    assert "process[second" not in out, out


@pytest.mark.ros1
@pytest.mark.skipif(not Path(DEBIAN).exists(), reason="Debian's roslaunch is not installed")
def test_stdin_and_bad_prefix_as_debians_roslaunch(tmp_path: Path) -> None:
    src = _package(tmp_path)
    (tmp_path / "read.launch").write_text(READ_LAUNCH)
    (tmp_path / "prefix.launch").write_text(PREFIX_LAUNCH)
    for command, env in ((OURS, _ours_env(tmp_path, src)), (DEBIAN, _debian_env(tmp_path, src))):
        code, out = _roslaunch(command, tmp_path / "read.launch", env, "forward\n")
        assert "read from the terminal: [forward]" in out, (command, out)
        assert code == 0, (command, out)
        code, out = _roslaunch(command, tmp_path / "prefix.launch", env, "")
        assert code == 1, (command, out)
        for line in BAD_PREFIX_LINES:
            assert line in out, (command, out)
        assert "process[second" not in out, (command, out)
        (tmp_path / "plain.launch").write_text(NO_SHEBANG_LAUNCH)
        code, out = _roslaunch(command, tmp_path / "plain.launch", env, "")
        assert code == 1, (command, out)
        assert "Unable to launch [plain" in out and NO_SHEBANG_LINE in out, (command, out)
        assert "process[second" not in out, (command, out)

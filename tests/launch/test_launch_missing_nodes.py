"""A node roslaunch cannot start (its package or its executable is missing) is reported with ROS 1's
line and the others start, as Debian's roslaunch does (robot launch files name
robot_state_publisher and friends that a machine may lack)."""

from __future__ import annotations

import os
import subprocess
import sys
import time
import xmlrpc.client
from pathlib import Path

import pytest

from ninjemys import testing

LAUNCH = """<launch>
  <node pkg="nosuch_pkg" type="nosuch_node" name="ghost"/>
  <node pkg="rosout" type="no_such_exe" name="ghost2"/>
  <node pkg="rosout" type="rosout" name="extra_rosout" required="false"/>
</launch>
"""
MISSING_EXE = (
    "ERROR: cannot launch node of type [rosout/no_such_exe]: Cannot locate node of type [no_such_exe] in "
    "package [rosout]. Make sure file exists in package path and permission is set to executable (chmod +x)"
)


def _run(command: list[str], tmp: Path, env: dict[str, str]) -> tuple[str, list[str]]:
    port = testing.free_port()
    uri = f"http://localhost:{port}/"
    proc = subprocess.Popen(
        [*command, "-p", str(port), str(tmp / "m.launch")],
        env=dict(env, ROS_MASTER_URI=uri, ROS_HOSTNAME="localhost"),
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
    )
    nodes: list[str] = []
    try:
        deadline = time.monotonic() + 60
        while time.monotonic() < deadline and "/extra_rosout" not in nodes:
            try:
                state = xmlrpc.client.ServerProxy(uri).getSystemState("/test")[2]
                nodes = sorted({n for _, ns in state[0] + state[1] + state[2] for n in ns})
            except OSError:
                pass
            time.sleep(0.2)
    finally:
        proc.send_signal(2)
        try:
            out = proc.communicate(timeout=30)[0]
        except subprocess.TimeoutExpired:
            testing.kill_tree(proc)
            out = proc.communicate()[0]
    return out.replace("\x1b[31m", "").replace("\x1b[0m", "").replace("\x1b[1m", ""), nodes


def test_the_others_start_and_each_missing_node_gets_one_line(tmp_path: Path) -> None:
    (tmp_path / "m.launch").write_text(LAUNCH)
    env = dict(os.environ, ROS_HOME=str(tmp_path))
    out, nodes = _run([str(Path(sys.executable).parent / "roslaunch")], tmp_path, env)
    assert "/extra_rosout" in nodes, out
    assert "ERROR: cannot launch node of type [nosuch_pkg/nosuch_node]: nosuch_pkg\nROS path [0]=" in out
    assert out.count(MISSING_EXE) == 1, out


@pytest.mark.ros1
@pytest.mark.skipif(not Path("/usr/bin/roslaunch").exists(), reason="Debian's roslaunch is not installed")
def test_same_lines_as_debians_roslaunch(tmp_path: Path) -> None:
    (tmp_path / "m.launch").write_text(LAUNCH)
    ours, our_nodes = _run(
        [str(Path(sys.executable).parent / "roslaunch")], tmp_path, dict(os.environ, ROS_HOME=str(tmp_path))
    )
    ros1_env = {"PATH": "/usr/bin:/bin", "HOME": str(tmp_path), "ROS_HOME": str(tmp_path), "LANG": "C.UTF-8"}
    theirs, their_nodes = _run(["/usr/bin/roslaunch"], tmp_path, ros1_env)
    assert "/extra_rosout" in our_nodes and "/extra_rosout" in their_nodes, theirs
    for out in (ours, theirs):
        assert "ERROR: cannot launch node of type [nosuch_pkg/nosuch_node]: nosuch_pkg\nROS path [0]=" in out
        assert out.count(MISSING_EXE) == 1, out


def test_a_file_that_is_not_executable_gets_the_same_line(tmp_path: Path) -> None:
    pkg = tmp_path / "src" / "noexec_pkg"
    pkg.mkdir(parents=True)
    (pkg / "package.xml").write_text(
        '<package format="2"><name>noexec_pkg</name><version>0.0.1</version><description>d</description>'
        '<maintainer email="dev@example.com">d</maintainer><license>BSD</license></package>'
    )
    (pkg / "node.py").write_text("print('never run')\n")
    (tmp_path / "m.launch").write_text(
        '<launch><node pkg="noexec_pkg" type="node.py" name="a"/>'
        '<node pkg="rosout" type="rosout" name="extra_rosout"/></launch>'
    )
    env = dict(os.environ, ROS_HOME=str(tmp_path), ROS_PACKAGE_PATH=str(tmp_path / "src"))
    out, nodes = _run([str(Path(sys.executable).parent / "roslaunch")], tmp_path, env)
    assert "/extra_rosout" in nodes
    assert (
        "ERROR: cannot launch node of type [noexec_pkg/node.py]: Cannot locate node of type [node.py]" in out
    )
    assert "chmod +x" in out


ONLY_MISSING = """<launch>
  <param name="kept" value="1"/>
  <node pkg="nosuch_pkg" type="nosuch_node" name="ghost"/>
</launch>
"""


def _run_to_exit(command: list[str], tmp: Path, env: dict[str, str]) -> subprocess.CompletedProcess[str]:
    """roslaunch against a running master (with a master of its own it would keep the master up)."""
    with testing.run_master(env=dict(os.environ, ROS_HOME=str(tmp))) as uri:
        return subprocess.run(
            [*command, str(tmp / "m.launch")],
            env=dict(env, ROS_MASTER_URI=uri, ROS_HOSTNAME="localhost"),
            stdout=subprocess.PIPE,
            stderr=subprocess.STDOUT,
            text=True,
            timeout=120,
            check=False,
        )


def _tail(out: str) -> list[str]:
    """The missing node's line and the three closing lines (stderr and stdout interleave differently)."""
    plain = out.replace("\x1b[31m", "").replace("\x1b[0m", "").replace("\x1b[1m", "")
    lines = [line.split("\x07")[-1] for line in plain.splitlines()]
    errors = [line.split("]:")[0] + "]:" for line in lines if line.startswith("ERROR: cannot launch node")]
    start = lines.index("No processes to monitor") if "No processes to monitor" in lines else len(lines)
    return errors + lines[start : start + 3]


def test_nothing_left_to_run_ends_with_ros1s_lines(tmp_path: Path) -> None:
    """The book code's case (a launch file of one node that cannot start): ROS 1 prints "No processes to
    monitor" and the process monitor's shutdown, and exits 0."""
    (tmp_path / "m.launch").write_text(ONLY_MISSING)
    done = _run_to_exit(
        [str(Path(sys.executable).parent / "roslaunch")], tmp_path, dict(os.environ, ROS_HOME=str(tmp_path))
    )
    assert done.returncode == 0, done.stdout
    assert _tail(done.stdout) == [
        "ERROR: cannot launch node of type [nosuch_pkg/nosuch_node]:",
        "No processes to monitor",
        "shutting down processing monitor...",
        "... shutting down processing monitor complete",
    ]


@pytest.mark.ros1
@pytest.mark.skipif(not Path("/usr/bin/roslaunch").exists(), reason="Debian's roslaunch is not installed")
def test_nothing_left_to_run_as_debians_roslaunch(tmp_path: Path) -> None:
    (tmp_path / "m.launch").write_text(ONLY_MISSING)
    ours = _run_to_exit(
        [str(Path(sys.executable).parent / "roslaunch")], tmp_path, dict(os.environ, ROS_HOME=str(tmp_path))
    )
    ros1_env = {"PATH": "/usr/bin:/bin", "HOME": str(tmp_path), "ROS_HOME": str(tmp_path), "LANG": "C.UTF-8"}
    theirs = _run_to_exit(["/usr/bin/roslaunch"], tmp_path, ros1_env)
    assert ours.returncode == theirs.returncode == 0
    assert _tail(ours.stdout) == _tail(theirs.stdout) != []

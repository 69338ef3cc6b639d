"""A program started with SIGINT ignored still stops on SIGINT, as ROS 1's do.

A parent that ignores SIGINT passes that on through exec (a background job of a shell script, a
supervisor cleaning up, a test runner). rospy and roscpp install their own SIGINT handler at init, so
Debian's rostopic, rosout and roscore stop on SIGINT regardless; ours must too, or roslaunch's and a
test's SIGINT leaves them running until they are killed.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from collections.abc import Iterator

import pytest

from ninjemys.master.core import MasterThread
from ninjemys.testing import ROS1_BIN, have_ros1, kill_tree, ninjemys_bin, ros1_env, run_real_master

# Each command runs in a child whose SIGINT is ignored before exec, exactly what a parent ignoring it does.
_IGNORING_PARENT = "import os, signal, sys; signal.signal(signal.SIGINT, signal.SIG_IGN); os.execv(sys.argv[1], sys.argv[1:])"

_OURS = {
    "rostopic echo": ["rostopic", "echo", "/sigint_probe"],
    "rostopic pub -r": ["rostopic", "pub", "-r", "5", "/sigint_probe", "std_msgs/String", "data: hi"],
    "rosout": ["rosrun", "rosout", "rosout"],
}


def _stops_on_sigint(argv: list[str], env: dict[str, str], settle: float = 2.0) -> float:
    """Start ``argv`` with SIGINT ignored, send SIGINT after ``settle`` s; return how long it took to exit
    with status 0 (the test fails if it does not exit within 10 s)."""
    proc = subprocess.Popen(
        [sys.executable, "-c", _IGNORING_PARENT, *argv],
        env=env,
        stdin=subprocess.DEVNULL,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
    )
    try:
        time.sleep(settle)
        assert proc.poll() is None, (
            f"{argv} ended early: {proc.stderr.read().decode() if proc.stderr else ''}"
        )
        sent = time.monotonic()
        proc.send_signal(signal.SIGINT)
        try:
            code = proc.wait(10)
        except subprocess.TimeoutExpired:
            pytest.fail(f"{' '.join(argv)} started with SIGINT ignored did not stop on SIGINT within 10 s")
        assert code == 0, f"{argv} exited {code}"
        return time.monotonic() - sent
    finally:
        if proc.poll() is None:
            kill_tree(proc)
        if proc.stderr:
            proc.stderr.close()


@pytest.fixture
def our_master() -> Iterator[str]:
    with MasterThread() as uri:
        yield uri


@pytest.mark.parametrize("label", sorted(_OURS))
def test_ours_stop_on_sigint_when_started_ignoring_it(label: str, our_master: str, tmp_path) -> None:
    command, *args = _OURS[label]
    env = dict(os.environ, ROS_MASTER_URI=our_master, ROS_LOG_DIR=str(tmp_path), ROS_HOME=str(tmp_path))
    _stops_on_sigint([ninjemys_bin(command), *args], env)


def test_roscore_stops_on_sigint_when_started_ignoring_it(tmp_path) -> None:
    from ninjemys.net.addresses import free_port

    env = dict(os.environ, ROS_LOG_DIR=str(tmp_path), ROS_HOME=str(tmp_path))
    _stops_on_sigint([ninjemys_bin("roscore"), "-p", str(free_port())], env)


def test_a_node_started_by_rosrun_stops_on_sigint_when_started_ignoring_it(our_master: str, tmp_path) -> None:
    env = dict(os.environ, ROS_MASTER_URI=our_master, ROS_LOG_DIR=str(tmp_path), ROS_HOME=str(tmp_path))
    _stops_on_sigint(
        [
            ninjemys_bin("rosrun"),
            "tf2_ros",
            "static_transform_publisher",
            "0",
            "0",
            "0",
            "0",
            "0",
            "0",
            "a",
            "b",
        ],
        env,
    )


@pytest.mark.ros1
@pytest.mark.skipif(not have_ros1(), reason="Debian's ROS 1 is not installed")
def test_ros1_does_the_same(tmp_path) -> None:
    """The reference: Debian's rostopic and rosout stop on SIGINT though started ignoring it."""
    with run_real_master() as uri:
        env = ros1_env(uri, ROS_LOG_DIR=str(tmp_path), ROS_HOME=str(tmp_path))
        _stops_on_sigint([str(ROS1_BIN / "rostopic"), "echo", "/sigint_probe"], env)
        _stops_on_sigint(["/usr/lib/rosout/rosout"], env)

"""Public test helpers: free ports, and locating Debian's real ROS 1 for comparison tests.

Kept dependency-free so user test suites (and ours) can import it without starting anything.
"""

from __future__ import annotations

import contextlib
import os
from collections.abc import Iterator
from pathlib import Path
from typing import Any

from ninjemys.commands import command_path
from ninjemys.net.addresses import free_port as free_port  # re-exported: tests and users take it from here

#: Debian's real ROS 1 runs under the system interpreter, never the project's venv.
ROS1_PYTHON = "/usr/bin/python3"
ROS1_BIN = Path("/usr/bin")


def have_ros1() -> bool:
    """True when Debian's ROS 1 (rospy + rosmaster under /usr/bin/python3) is installed."""
    return Path(ROS1_PYTHON).exists() and Path("/usr/lib/python3/dist-packages/rospy").is_dir()


def ros1_env(master_uri: str, **extra: str) -> dict[str, str]:
    """An environment for running real ROS 1 programs: no venv, no ninjemys on the path."""
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "VIRTUAL_ENV", "PYTHONHOME")}
    env["PATH"] = "/usr/bin:/bin:/usr/sbin:/sbin"
    env["ROS_MASTER_URI"] = master_uri
    env.setdefault("ROS_HOSTNAME", "localhost")
    env.update(extra)
    return env


def ros1_built_interfaces(dest: str | os.PathLike[str]) -> Path:
    """A copy of the shipped interface packages as a ROS 1 build leaves them, for real rosmsg/rospack.

    catkin runs actionlib_msgs' genaction.py over every ``.action`` and writes the seven generated
    ``.msg`` files into the package's share ``msg/``; real tools list and show them from there. This
    runs Debian's own genaction.py the same way, so a comparison against real ROS 1 sees what a built
    installation holds. Returns the directory to put on ``ROS_PACKAGE_PATH``.
    """
    import shutil
    import subprocess

    from ninjemys.idl.search import SHIPPED_ROOT

    root = Path(dest) / "interfaces"
    shutil.copytree(SHIPPED_ROOT, root)
    for action in sorted(root.glob("*/action/*.action")):
        subprocess.run(
            [
                ROS1_PYTHON,
                "/usr/lib/actionlib_msgs/genaction.py",
                str(action),
                "-o",
                str(action.parent.parent / "msg"),
            ],
            env=ros1_env("http://localhost:11311"),
            capture_output=True,
            check=True,
            timeout=60,
        )
    return root


def ninjemys_bin(command: str) -> str:
    """Full path of one of our console scripts (the venv's bin/, next to the running interpreter)."""
    return command_path(command)


def FakeClock(start: float = 0.0):  # noqa: N802 - reads as a class at call sites
    """A simulated ROS clock that a test drives by hand (``clock.advance(0.5)``, ``clock.set(3.0)``).

    Returns a :class:`ninjemys.node.clock.FakeClock`; imported on call so this module stays light.
    """
    from ninjemys.node.clock import FakeClock as _FakeClock

    return _FakeClock(start)


def reset_rospy() -> None:
    """Shut down the rospy node of this process (if any) and forget all of rospy's state, in-process.

    rospy allows one ``init_node`` per process; after this, the next ``rospy.init_node`` starts a
    new node, so rospy tests need no subprocess each. User shutdown hooks run first, as on a real
    shutdown; handles (Publishers, Subscribers, Services) of the old node stay unregistered.
    Typical use is a fixture::

        @pytest.fixture
        def rospy_node(master_uri, monkeypatch):
            monkeypatch.setenv("ROS_MASTER_URI", master_uri)
            yield
            ninjemys.testing.reset_rospy()
    """
    import sys

    core = sys.modules.get("rospy.core")
    if core is not None:  # rospy never imported: nothing to reset
        core._reset()


@contextlib.contextmanager
def run_master(
    port: int | None = None, env: dict[str, str] | None = None, timeout: float = 20.0
) -> Iterator[str]:
    """Start our ``roscore`` on a free port, yield its URI once it answers, kill it afterwards.

    ``env`` replaces the child's environment (ROS_HOME and ROS_LOG_DIR are inherited by default,
    so logs land in the test's own directory); its output is discarded.
    """
    import subprocess
    import time

    from ninjemys.net import auth

    port = port or free_port()
    uri = f"http://localhost:{port}/"
    child_env = dict(os.environ if env is None else env)
    child_env.setdefault("ROS_HOSTNAME", "localhost")
    child_env["ROS_MASTER_URI"] = uri
    proc = subprocess.Popen(
        [ninjemys_bin("roscore"), "-p", str(port)],
        env=child_env,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
        stdin=subprocess.DEVNULL,
    )
    try:
        deadline = time.monotonic() + timeout
        while True:
            try:
                auth.server_proxy(uri).getPid("/run_master")
                break
            except OSError:
                if proc.poll() is not None:
                    raise RuntimeError(f"roscore -p {port} exited with {proc.returncode}") from None
                if time.monotonic() > deadline:
                    raise RuntimeError(f"roscore -p {port} did not answer within {timeout} s") from None
                time.sleep(0.02)
        yield uri
    finally:
        proc.kill()
        proc.wait()


def descendants(pid: int) -> list[int]:
    """Every live descendant of ``pid`` (from /proc), children before grandchildren.

    Needed because roslaunch puts each child (rosmaster, rosout) in its own session, so killing the
    parent's process group leaves them running.
    """
    children: dict[int, list[int]] = {}
    for entry in Path("/proc").iterdir():
        if not entry.name.isdigit():
            continue
        try:
            stat = (entry / "stat").read_text()
        except OSError:
            continue
        ppid = int(stat.rsplit(")", 1)[1].split()[1])
        children.setdefault(ppid, []).append(int(entry.name))
    found: list[int] = []
    frontier = [pid]
    while frontier:
        nxt = []
        for parent in frontier:
            for child in children.get(parent, []):
                found.append(child)
                nxt.append(child)
        frontier = nxt
    return found


def kill_tree(proc: Any) -> None:
    """SIGKILL a Popen'd process and all of its descendants, then reap it."""
    import signal

    for pid in [*descendants(proc.pid), proc.pid]:
        try:
            os.kill(pid, signal.SIGKILL)
        except ProcessLookupError:
            pass
    proc.wait()


@contextlib.contextmanager
def run_real_roscore(ros_home: str | os.PathLike[str], timeout: float = 30.0) -> Iterator[str]:
    """Debian's /usr/bin/roscore on a free port; yields its URI once /rosout is up; kills the whole tree."""
    import subprocess
    import time

    from ninjemys.net import auth

    port = free_port()
    uri = f"http://localhost:{port}/"
    proc = subprocess.Popen(
        ["/usr/bin/roscore", "-p", str(port)],
        env=ros1_env(uri, ROS_HOME=str(ros_home)),
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
        stdin=subprocess.DEVNULL,
        start_new_session=True,
    )
    try:
        deadline = time.monotonic() + timeout
        while True:
            try:
                code, _, state = auth.server_proxy(uri).getSystemState("/run_real_roscore")
                if code == 1 and any(topic == "/rosout_agg" for topic, _ in state[0]):
                    break
            except OSError:
                pass
            if proc.poll() is not None:
                raise RuntimeError(f"/usr/bin/roscore -p {port} exited with {proc.returncode}")
            if time.monotonic() > deadline:
                raise RuntimeError(f"/usr/bin/roscore -p {port} did not bring up /rosout within {timeout} s")
            time.sleep(0.1)
        yield uri
    finally:
        kill_tree(proc)

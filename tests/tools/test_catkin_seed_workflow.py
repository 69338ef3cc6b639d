"""The seeds' workflow end to end, typed as a new user would, in a temp dir.

mkdir -p catkin_ws/src; catkin_create_pkg first_pkg std_msgs rospy; talker.py/listener.py in the
seeds' style into scripts/; chmod +x; catkin_make; source devel/setup.bash; rosrun first_pkg
talker.py; roslaunch first_pkg first_pkg.launch -> the listener hears the talker; a custom .msg in
the package is importable after catkin_make.
"""

from __future__ import annotations

import os
import signal
import subprocess
import textwrap
import time
from pathlib import Path

import pytest

from ninjemys.testing import ninjemys_bin

TALKER = textwrap.dedent(
    """\
    #!/usr/bin/env python3
    import rospy
    from std_msgs.msg import String

    def talker():
        pub = rospy.Publisher('chatter', String, queue_size=10)
        rospy.init_node('talker', anonymous=True)
        rate = rospy.Rate(10) # 10hz
        while not rospy.is_shutdown():
            hello_str = "hello world %s" % rospy.get_time()
            rospy.loginfo(hello_str)
            pub.publish(hello_str)
            rate.sleep()

    if __name__ == '__main__':
        try:
            talker()
        except rospy.ROSInterruptException:
            pass
    """
)

LISTENER = textwrap.dedent(
    """\
    #!/usr/bin/env python3
    import rospy
    from std_msgs.msg import String

    def callback(data):
        rospy.loginfo(rospy.get_caller_id() + "I heard %s", data.data)

    def listener():
        rospy.init_node('listener', anonymous=True)
        rospy.Subscriber("chatter", String, callback)
        rospy.spin()

    if __name__ == '__main__':
        listener()
    """
)

LAUNCH = """<launch>
  <node name="talker" pkg="first_pkg" type="talker.py" output="screen"/>
  <node name="listener" pkg="first_pkg" type="listener.py" output="screen"/>
</launch>
"""


def shell(cmd: str, cwd: Path, env: dict[str, str], timeout: float = 120) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        ["bash", "-c", cmd], cwd=cwd, env=env, capture_output=True, text=True, timeout=timeout, check=False
    )


@pytest.fixture
def user_env(tmp_path: Path, port: int) -> dict[str, str]:
    """A fresh shell: our commands on PATH (as after pip install), nothing ROS-related set but the port."""
    env = {k: v for k, v in os.environ.items() if not k.startswith(("ROS_PACKAGE_PATH", "CMAKE_PREFIX_PATH"))}
    env.pop("PYTHONPATH", None)
    env["PATH"] = f"{Path(ninjemys_bin('catkin_make')).parent}:/usr/bin:/bin"
    env["ROS_MASTER_URI"] = f"http://localhost:{port}"
    env["ROS_HOME"] = str(tmp_path / "ros_home")
    return env


@pytest.fixture
def workspace(tmp_path: Path, user_env: dict[str, str]) -> Path:
    ws = tmp_path / "catkin_ws"
    steps = "mkdir -p catkin_ws/src && cd catkin_ws/src && catkin_create_pkg first_pkg std_msgs rospy"
    result = shell(steps, tmp_path, user_env)
    assert result.returncode == 0, result.stderr
    pkg = ws / "src" / "first_pkg"
    (pkg / "scripts").mkdir()
    (pkg / "scripts" / "talker.py").write_text(TALKER)
    (pkg / "scripts" / "listener.py").write_text(LISTENER)
    (pkg / "launch").mkdir()
    (pkg / "launch" / "first_pkg.launch").write_text(LAUNCH)
    (pkg / "msg").mkdir()
    (pkg / "msg" / "Reading.msg").write_text("Header header\nfloat32 temperature\n")
    result = shell(
        "chmod +x src/first_pkg/scripts/talker.py src/first_pkg/scripts/listener.py && catkin_make",
        ws,
        user_env,
    )
    assert result.returncode == 0, result.stderr
    return ws


def test_custom_message_importable_after_catkin_make(workspace: Path, user_env: dict[str, str]) -> None:
    code = "from first_pkg.msg import Reading; r = Reading(temperature=21.5); print(r._type, r.temperature)"
    result = shell(f"source devel/setup.bash && python3 -c '{code}'", workspace, user_env)
    assert result.returncode == 0, result.stderr
    assert result.stdout.strip() == "first_pkg/Reading 21.5"


def test_roslaunch_listener_hears_talker(workspace: Path, user_env: dict[str, str]) -> None:
    proc = subprocess.Popen(
        ["bash", "-c", "source devel/setup.bash && exec roslaunch first_pkg first_pkg.launch"],
        cwd=workspace,
        env=user_env,
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
    )
    heard = False
    lines: list[str] = []
    try:
        deadline = time.monotonic() + 90
        assert proc.stdout is not None
        for line in proc.stdout:
            lines.append(line)
            if "I heard hello world" in line:
                heard = True
                break
            if time.monotonic() > deadline:
                break
        proc.send_signal(signal.SIGINT)
        assert proc.wait(30) == 0
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
    assert heard, "".join(lines[:30]) + "...\n" + "".join(lines[-10:])  # roslaunch's start-up, then the end


def test_rosrun_talker_after_sourcing(workspace: Path, user_env: dict[str, str]) -> None:
    core = subprocess.Popen(
        [ninjemys_bin("roscore"), "-p", user_env["ROS_MASTER_URI"].rsplit(":", 1)[1]],
        env=user_env,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    talker = None
    try:
        talker = subprocess.Popen(
            ["bash", "-c", "source devel/setup.bash && exec rosrun first_pkg talker.py"],
            cwd=workspace,
            env=user_env,
            stdout=subprocess.PIPE,
            stderr=subprocess.STDOUT,
            text=True,
        )
        assert talker.stdout is not None
        seen = []
        for line in talker.stdout:
            seen.append(line)
            if "hello world" in line or len(seen) > 50:
                break
        assert any("hello world" in line for line in seen), "".join(seen)
    finally:
        for proc in (talker, core):
            if proc is not None and proc.poll() is None:
                proc.send_signal(signal.SIGINT)
                try:
                    proc.wait(10)
                except subprocess.TimeoutExpired:
                    proc.kill()
                    proc.wait()

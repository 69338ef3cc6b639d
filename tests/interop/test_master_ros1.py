"""Real ROS 1 (Debian's rospy and command-line tools) against our roscore."""

from __future__ import annotations

import socket
import subprocess
import sys
import textwrap
import time
from collections.abc import Iterator
from pathlib import Path

import pytest
import yaml

from ninjemys.master.client import MasterClient
from ninjemys.testing import ROS1_PYTHON, ros1_env, run_master

pytestmark = pytest.mark.ros1

TALKER = textwrap.dedent(
    """
    import rospy
    from std_msgs.msg import String
    rospy.init_node("talker")
    pub = rospy.Publisher("chatter", String, queue_size=10)
    rate = rospy.Rate(20)
    i = 0
    while not rospy.is_shutdown():
        rospy.loginfo("hello %d", i)
        pub.publish(String("hello %d" % i))
        i += 1
        rate.sleep()
    """
)

LISTENER = textwrap.dedent(
    """
    import sys, rospy
    from std_msgs.msg import String
    got = []
    def cb(msg):
        got.append(msg.data)
        if len(got) >= 3:
            rospy.signal_shutdown("done")
    rospy.init_node("listener")
    rospy.Subscriber("chatter", String, cb)
    rospy.spin()
    print("\\n".join(got))
    """
)


def ros1(args: list[str], uri: str, timeout: float = 30, **kw: object) -> subprocess.CompletedProcess[str]:
    return subprocess.run(args, env=ros1_env(uri), capture_output=True, text=True, timeout=timeout, **kw)  # type: ignore[call-overload]


@pytest.fixture
def master() -> Iterator[str]:
    with run_master() as uri:
        yield uri


@pytest.fixture
def talker(master: str) -> Iterator[subprocess.Popen[str]]:
    proc = subprocess.Popen(
        [ROS1_PYTHON, "-c", TALKER],
        env=ros1_env(master),
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        text=True,
    )
    try:
        client = MasterClient(master, "/probe")
        deadline = time.monotonic() + 30
        while not any(t == "/chatter" for t, _ in client.get_published_topics()):
            assert proc.poll() is None, proc.communicate()
            assert time.monotonic() < deadline
            time.sleep(0.05)
        yield proc
    finally:
        proc.kill()
        proc.wait()


def test_rospy_talker_and_listener(master: str, talker: subprocess.Popen[str]) -> None:
    res = ros1([ROS1_PYTHON, "-c", LISTENER], master, timeout=60)
    assert res.returncode == 0, res.stderr
    lines = res.stdout.split()
    assert len([line for line in res.stdout.splitlines() if line.startswith("hello")]) >= 3, lines


def test_rostopic(master: str, talker: subprocess.Popen[str]) -> None:
    listing = ros1(["/usr/bin/rostopic", "list"], master)
    assert {"/chatter", "/rosout", "/rosout_agg"} <= set(listing.stdout.split()), listing
    info = ros1(["/usr/bin/rostopic", "info", "/chatter"], master)
    assert "Type: std_msgs/String" in info.stdout and "/talker" in info.stdout, info
    echo = ros1(["/usr/bin/rostopic", "echo", "-n", "1", "/chatter"], master)
    assert echo.stdout.startswith('data: "hello'), echo


def test_rosnode(master: str, talker: subprocess.Popen[str]) -> None:
    listing = ros1(["/usr/bin/rosnode", "list"], master)
    assert {"/talker", "/rosout"} <= set(listing.stdout.split()), listing
    info = ros1(["/usr/bin/rosnode", "info", "/talker"], master)
    assert "/chatter [std_msgs/String]" in info.stdout, info
    ping = ros1(["/usr/bin/rosnode", "ping", "-c", "1", "/talker"], master)
    assert "reply from" in ping.stdout, ping
    kill = ros1(["/usr/bin/rosnode", "kill", "/talker"], master)
    assert "killed" in kill.stdout, kill
    talker.wait(timeout=20)


def test_rosparam(master: str, tmp_path: Path) -> None:
    assert ros1(["/usr/bin/rosparam", "set", "/gain", "2.5"], master).returncode == 0
    assert ros1(["/usr/bin/rosparam", "get", "/gain"], master).stdout.strip() == "2.5"
    (tmp_path / "p.yaml").write_text("robot:\n  name: r1\n  wheels: 3\n")
    load = ros1(["/usr/bin/rosparam", "load", str(tmp_path / "p.yaml")], master)
    assert load.returncode == 0, load
    assert yaml.safe_load(ros1(["/usr/bin/rosparam", "get", "/robot"], master).stdout) == {
        "name": "r1",
        "wheels": 3,
    }
    dump = ros1(["/usr/bin/rosparam", "dump", str(tmp_path / "out.yaml"), "/robot"], master)
    assert dump.returncode == 0 and yaml.safe_load((tmp_path / "out.yaml").read_text())["name"] == "r1"
    names = ros1(["/usr/bin/rosparam", "list"], master).stdout.split()
    assert {"/gain", "/robot/name", "/run_id", "/rosversion"} <= set(names)
    assert ros1(["/usr/bin/rosparam", "delete", "/robot"], master).returncode == 0
    # 64-bit integers: real rospy cannot send them, but receives them as <i8> from our master
    MasterClient(master, "/setter").set_param("/robot/big", 10**10)
    assert ros1(["/usr/bin/rosparam", "get", "/robot/big"], master).stdout.strip() == str(10**10)
    assert ros1(["/usr/bin/rosparam", "delete", "/robot"], master).returncode == 0
    missing = ros1(["/usr/bin/rosparam", "get", "/robot"], master)
    assert missing.returncode != 0


def test_rosservice(master: str, talker: subprocess.Popen[str]) -> None:
    listing = ros1(["/usr/bin/rosservice", "list"], master)
    assert "/talker/get_loggers" in listing.stdout.split(), listing
    call = ros1(["/usr/bin/rosservice", "call", "/talker/get_loggers"], master)
    assert call.returncode == 0 and "loggers:" in call.stdout, call


def test_rospy_logs_reach_rosout_agg_and_rosout_log(
    master: str, talker: subprocess.Popen[str], tmp_path: Path
) -> None:
    echo = ros1(["/usr/bin/rostopic", "echo", "-n", "1", "/rosout_agg/msg"], master, timeout=60)
    assert "hello" in echo.stdout, echo
    run_id = MasterClient(master, "/probe").get_param("/run_id")
    import os

    log_file = Path(os.environ["ROS_HOME"]) / "log" / run_id / "rosout.log"
    deadline = time.monotonic() + 20
    while "INFO /talker [" not in log_file.read_text():
        assert time.monotonic() < deadline, log_file.read_text()[-2000:]
        time.sleep(0.1)
    line = next(line for line in log_file.read_text().splitlines() if "INFO /talker [" in line)
    # <sec>.<nsec> INFO /talker [file:line(function)] [topics: ...] hello N
    stamp, level, node, rest = line.split(" ", 3)
    assert level == "INFO" and node == "/talker" and len(stamp.split(".")[1]) == 9
    assert "[topics: " in rest and "/chatter" in rest and rest.split("] ")[-1].startswith("hello")


def test_hostile_subscriber_does_not_stop_talker_and_listener(master: str) -> None:
    hole = socket.socket()
    hole.bind(("127.0.0.1", 0))
    hole.listen(50)
    try:
        api = f"http://127.0.0.1:{hole.getsockname()[1]}/"
        for i in range(6):
            MasterClient(master, f"/hostile{i}").register_subscriber("/chatter", "std_msgs/String", api)
        talker = subprocess.Popen(
            [ROS1_PYTHON, "-c", TALKER],
            env=ros1_env(master),
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
        )
        try:
            res = ros1([ROS1_PYTHON, "-c", LISTENER], master, timeout=60)
            assert res.returncode == 0 and res.stdout.count("hello") >= 3, res
            assert MasterClient(master, "/probe").get_pid() > 0
        finally:
            talker.kill()
            talker.wait()
    finally:
        hole.close()


if __name__ == "__main__":  # pragma: no cover
    sys.exit(pytest.main([__file__, "-v"]))


def test_same_name_shuts_down_the_old_rospy_node(master: str) -> None:
    first = subprocess.Popen(
        [ROS1_PYTHON, "-c", TALKER],
        env=ros1_env(master),
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    second = None
    try:
        client = MasterClient(master, "/probe")
        deadline = time.monotonic() + 30
        # rospy registers in the background: wait for all of it, or a late registration of the first
        # talker would (rightly) bump the second one
        wanted = {"/talker/get_loggers", "/talker/set_logger_level"}
        while not wanted <= {name for name, _ in client.get_system_state()[2]} or not any(
            t == "/chatter" for t, _ in client.get_published_topics()
        ):
            assert time.monotonic() < deadline
            time.sleep(0.05)
        first_api = client.lookup_node("/talker")
        second = subprocess.Popen(
            [ROS1_PYTHON, "-c", TALKER],
            env=ros1_env(master),
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
        )
        first.wait(timeout=30)  # the master told the old /talker to shut down
        assert client.lookup_node("/talker") != first_api
        assert second.poll() is None
    finally:
        for proc in (first, second):
            if proc is not None:
                proc.kill()
                proc.wait()


@pytest.mark.skipif(
    not Path("/usr/lib/rosout/rosout").exists(), reason="Debian's C++ rosout is not installed"
)
def test_roscpp_node_against_our_master(master: str) -> None:
    """Debian's rosout is a roscpp program: its XmlRpc++ client registers with and is found through us."""
    cpp = subprocess.Popen(
        ["/usr/lib/rosout/rosout", "__name:=rosout_cpp"],
        env=ros1_env(master),
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    try:
        client = MasterClient(master, "/probe")
        deadline = time.monotonic() + 30
        while True:
            pubs = dict((t, n) for t, n in client.get_system_state()[0])
            if "/rosout_cpp" in pubs.get("/rosout_agg", []):
                break
            assert cpp.poll() is None and time.monotonic() < deadline
            time.sleep(0.05)
        info = ros1(["/usr/bin/rosnode", "info", "/rosout_cpp"], master)
        assert "/rosout_cpp/get_loggers" in info.stdout and "Pid:" in info.stdout, info
        client.set_param("/cpp_check", 1)
        assert client.lookup_service("/rosout_cpp/get_loggers").startswith("rosrpc://")
    finally:
        cpp.kill()
        cpp.wait()

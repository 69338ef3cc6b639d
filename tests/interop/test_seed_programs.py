"""The seeds' talker and listener, read verbatim from the course text, run unmodified on ninjemys.

The programs are extracted from /work/shared/seeds at test time (never copied into the project), then
run as separate processes: both on ninjemys over our roscore, both on ninjemys over Debian's real
roscore, and mixed with Debian's real rospy in both directions.
"""

from __future__ import annotations

import os
import re
import subprocess
import sys
import time
from collections.abc import Iterator
from pathlib import Path

import pytest

from ninjemys.testing import ROS1_PYTHON, NodeProcess, ros1_env, run_master, run_real_roscore

SEEDS = Path(os.environ.get("NINJEMYS_SEEDS", Path(__file__).resolve().parents[3] / "shared" / "seeds"))
SEED = SEEDS / "000_7aec5b1f38a66cac.txt"
pytestmark = pytest.mark.skipif(not SEED.exists(), reason=f"seed text {SEED} not available")

INFO_LINE = r"^\[INFO\] \[\d+\.\d{6}\]: "


def _blocks(text: str) -> list[str]:
    return [b.strip("\n") + "\n" for b in re.findall(r"```\n(.*?)```", text, flags=re.S)]


def _seed_program(*must: str, without: str | None = None) -> str:
    """The first code block of the seed that contains every string in ``must`` (and not ``without``)."""
    for block in _blocks(SEED.read_text()):
        if all(m in block for m in must) and (without is None or without not in block):
            compile(block, "seed", "exec")
            return block
    raise AssertionError(f"no code block with {must} in {SEED}")


def talker_code() -> str:
    return _seed_program(
        "def talker():", "pub.publish(hello_str)", "ROSInterruptException", without="logfatal"
    )


def logging_talker_code() -> str:
    return _seed_program("def talker():", "rospy.logfatal(hello_str)")


def listener_code() -> str:
    return _seed_program("def listener():", "rospy.spin()", "if __name__ == '__main__':")


@pytest.fixture
def procs() -> Iterator[list[NodeProcess]]:
    started: list[NodeProcess] = []
    try:
        yield started
    finally:
        for p in started:
            p.kill()


def _run(
    procs: list[NodeProcess], tmp_path: Path, code: str, env: dict[str, str], python: str = sys.executable
) -> NodeProcess:
    path = tmp_path / f"seed_{len(procs)}.py"
    path.write_text(code)
    proc = NodeProcess([python, str(path)], env, tmp_path)
    procs.append(proc)
    return proc


def _our_env(master: str, tmp_path: Path) -> dict[str, str]:
    env = {
        k: v for k, v in os.environ.items() if k not in ("ROS_NAMESPACE", "ROS_LOG_DIR", "ROSCONSOLE_FORMAT")
    }
    env.update(
        ROS_MASTER_URI=master, ROS_HOME=str(tmp_path / "home"), ROS_HOSTNAME="localhost", PYTHONUNBUFFERED="1"
    )
    return env


@pytest.fixture(scope="module")
def our_master(tmp_path_factory: pytest.TempPathFactory) -> Iterator[str]:
    env = dict(os.environ, ROS_HOME=str(tmp_path_factory.mktemp("seed_master")), ROS_HOSTNAME="localhost")
    with run_master(env=env) as uri:
        yield uri


@pytest.fixture(scope="module")
def real_master(tmp_path_factory: pytest.TempPathFactory) -> Iterator[str]:
    """Debian's /usr/bin/roscore (rosmaster + rosout) on a free port, killed with all its children."""
    with run_real_roscore(tmp_path_factory.mktemp("real_roscore")) as uri:
        yield uri


def test_seed_blocks_are_found() -> None:
    assert "rospy.init_node('talker', anonymous=True)" in talker_code()
    assert 'rospy.Subscriber("chatter", String, callback)' in listener_code()


def _check_pair(talker: NodeProcess, listener: NodeProcess) -> None:
    sent = talker.wait_for(INFO_LINE + r"hello world (\d+\.\d+)$").group(1)
    heard = listener.wait_for(INFO_LINE + r"(/listener_\d+_\d+)I heard hello world (\d+\.\d+)$")
    assert float(heard.group(2)) >= float(sent) - 60
    # every message the listener heard is one the talker logged
    talked = {m.group(1) for line in talker.out if (m := re.search(r"hello world (\S+)$", line))}
    heard_all = [m.group(1) for line in listener.out if (m := re.search(r"I heard hello world (\S+)$", line))]
    assert heard_all and set(heard_all) <= talked | {heard_all[-1]}


def test_seed_talker_and_listener_over_our_roscore(our_master: str, procs, tmp_path: Path) -> None:
    env = _our_env(our_master, tmp_path)
    listener = _run(procs, tmp_path, listener_code(), env)
    talker = _run(procs, tmp_path, talker_code(), env)
    _check_pair(talker, listener)
    listener.interrupt()
    talker.interrupt()
    assert talker.wait(5) == 0 and listener.wait(5) == 0
    assert not any("Traceback" in line for line in talker.err + listener.err)


def test_seed_logging_talker_routes_levels(our_master: str, procs, tmp_path: Path) -> None:
    env = _our_env(our_master, tmp_path)
    talker = _run(procs, tmp_path, logging_talker_code(), env)
    talker.wait_for(INFO_LINE + r"hello world \d+\.\d+$")
    for level in ("WARN", "ERROR", "FATAL"):
        talker.wait_for(rf"^\[{level}\] \[\d+\.\d{{6}}\]: hello world \d+\.\d+$", stream="err")
    talker.interrupt()
    assert talker.wait(5) == 0
    assert all(line.startswith("[INFO]") for line in talker.out if line)
    assert not any(line.startswith("[INFO]") or "DEBUG" in line for line in talker.err)
    (log,) = (Path(env["ROS_HOME"]) / "log").glob("talker_*.log")
    text = log.read_text()
    assert "[rosout][DEBUG]" in text and "[rosout][CRITICAL]" in text


@pytest.mark.ros1
def test_seed_programs_over_real_roscore(real_master: str, procs, tmp_path: Path) -> None:
    env = _our_env(real_master, tmp_path)
    listener = _run(procs, tmp_path, listener_code(), env)
    talker = _run(procs, tmp_path, talker_code(), env)
    _check_pair(talker, listener)


@pytest.mark.ros1
def test_seed_talker_ours_listener_real_rospy(real_master: str, procs, tmp_path: Path) -> None:
    listener = _run(
        procs, tmp_path, listener_code(), ros1_env(real_master, ROS_HOME=str(tmp_path / "r")), ROS1_PYTHON
    )
    talker = _run(procs, tmp_path, talker_code(), _our_env(real_master, tmp_path))
    _check_pair(talker, listener)


@pytest.mark.ros1
def test_seed_talker_real_rospy_listener_ours(our_master: str, procs, tmp_path: Path) -> None:
    talker = _run(
        procs, tmp_path, talker_code(), ros1_env(our_master, ROS_HOME=str(tmp_path / "r")), ROS1_PYTHON
    )
    listener = _run(procs, tmp_path, listener_code(), _our_env(our_master, tmp_path))
    _check_pair(talker, listener)


ROSOUT_AGG_WATCHER = """
import rospy
from rosgraph_msgs.msg import Log
rospy.init_node('agg_watcher', anonymous=True)
def cb(m):
    if m.name.startswith('/talker_') and 'hello world' in m.msg:
        print('agg %d %s %s' % (m.level, m.name, ','.join(sorted(m.topics))), flush=True)
rospy.Subscriber('/rosout_agg', Log, cb)
print('ready', flush=True)
rospy.spin()
"""


@pytest.mark.ros1
def test_our_logs_reach_real_rosout_aggregator(real_master: str, procs, tmp_path: Path) -> None:
    watcher = _run(
        procs, tmp_path, ROSOUT_AGG_WATCHER, ros1_env(real_master, ROS_HOME=str(tmp_path / "r")), ROS1_PYTHON
    )
    watcher.wait_for("^ready$")
    _run(procs, tmp_path, talker_code(), _our_env(real_master, tmp_path))
    m = watcher.wait_for(r"^agg 2 (/talker_\d+_\d+) (\S+)$", timeout=30)
    assert "/chatter" in m.group(2).split(",") and "/rosout" in m.group(2).split(",")


@pytest.mark.ros1
def test_real_rosservice_drives_our_logger_services(real_master: str, procs, tmp_path: Path) -> None:
    env = _our_env(real_master, tmp_path)
    node = _run(
        procs,
        tmp_path,
        "import rospy\nrospy.init_node('levels')\nprint('up', flush=True)\nrospy.spin()\n",
        env,
    )
    node.wait_for("^up$")
    real = ros1_env(real_master, ROS_HOME=str(tmp_path / "r"))

    def rosservice(*args: str) -> str:
        deadline = time.monotonic() + 20
        while True:
            done = subprocess.run(
                ["/usr/bin/rosservice", *args], env=real, capture_output=True, text=True, timeout=30
            )
            if done.returncode == 0 or time.monotonic() > deadline:
                assert done.returncode == 0, done.stderr
                return done.stdout
            time.sleep(0.2)

    assert 'name: "rosout"' in rosservice("call", "/levels/get_loggers")
    rosservice("call", "/levels/set_logger_level", "rosout", "debug")
    out = rosservice("call", "/levels/get_loggers")
    assert 'level: "debug"' in out

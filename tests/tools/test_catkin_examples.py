"""examples/catkin_ws builds with catkin_make and every launch file does what its README says."""

from __future__ import annotations

import os
import shutil
import signal
import subprocess
import threading
import time
from pathlib import Path

import pytest

from ninjemys.testing import ninjemys_bin

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "catkin_ws"


@pytest.fixture(scope="module")
def built(tmp_path_factory: pytest.TempPathFactory) -> Path:
    ws = tmp_path_factory.mktemp("examples") / "catkin_ws"
    shutil.copytree(EXAMPLE, ws, ignore=shutil.ignore_patterns("build", "devel"))
    env = {k: v for k, v in os.environ.items() if k not in ("ROS_PACKAGE_PATH", "CMAKE_PREFIX_PATH")}
    result = subprocess.run(
        [ninjemys_bin("catkin_make")], cwd=ws, env=env, capture_output=True, text=True, check=False
    )
    assert result.returncode == 0, result.stderr
    return ws


def sourced_env(ws: Path, port: int, tmp_path: Path) -> dict[str, str]:
    env = dict(os.environ)
    env.update(
        ROS_PACKAGE_PATH=str(ws / "src"),
        PYTHONPATH=str(ws / "devel" / "lib" / "python3" / "dist-packages"),
        CMAKE_PREFIX_PATH=str(ws / "devel"),
        ROS_MASTER_URI=f"http://localhost:{port}",
        ROS_HOME=str(tmp_path / "ros_home"),
    )
    return env


def launch_until(args: list[str], env: dict[str, str], wanted: list[str], timeout: float = 60) -> list[str]:
    """Run roslaunch until every ``wanted`` text was printed (or timeout), then Ctrl-C it."""
    proc = subprocess.Popen(
        [ninjemys_bin("roslaunch"), *args],
        env=env,
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
    )
    lines: list[str] = []
    try:
        missing = set(wanted)
        deadline = time.monotonic() + timeout
        assert proc.stdout is not None
        # a reader thread, so a launch that goes quiet cannot block the test past its deadline
        reader = threading.Thread(target=lambda: lines.extend(proc.stdout), daemon=True)
        reader.start()
        while missing and time.monotonic() < deadline and proc.poll() is None:
            time.sleep(0.1)
            text = "".join(lines)
            missing = {w for w in missing if w not in text}
        proc.send_signal(signal.SIGINT)
        proc.wait(30)
        reader.join(10)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
    return lines


@pytest.mark.parametrize(
    ("args", "wanted"),
    [
        (["first_pkg", "first_pkg.launch"], ["I heard hello world"]),
        (
            ["test_pub_sub", "animals.launch", "cat_msg:=Purr"],
            ["I heard : Click_and_Squeak", "I heard : Purr"],
        ),
        (["basic_comms", "readings.launch"], [".5 at ", "I heard hello world"]),
        (["name_roll", "name_roll.launch", "name:=Grace", "roll:=7"], ["Student Grace has roll number: 7"]),
    ],
    ids=["first_pkg", "animals", "custom_msg", "name_roll"],
)
def test_example_launch(built: Path, port: int, tmp_path: Path, args: list[str], wanted: list[str]) -> None:
    lines = launch_until(args, sourced_env(built, port, tmp_path), wanted)
    text = "".join(lines)
    for w in wanted:
        assert w in text, text[-3000:]

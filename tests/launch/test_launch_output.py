"""output="screen" passes a node's stdout and stderr through unchanged, as ROS 1's roslaunch does
(the node inherits roslaunch's streams); ``--prefix-output`` or NINJEMYS_LAUNCH_PREFIX=1 print each
line behind ``[process-name]`` instead."""

from __future__ import annotations

import re
import subprocess
from pathlib import Path

import pytest

from ninjemys.testing import have_ros1, ninjemys_bin, ros1_env

from .conftest import write_launch

NODE = '<node name="streams" pkg="corpus_run" type="streams.py" output="{output}" required="true"/>'


def _roslaunch(cmd: list[str], env: dict[str, str]) -> subprocess.CompletedProcess[str]:
    return subprocess.run(cmd, env=env, capture_output=True, text=True, timeout=90, check=False)


@pytest.mark.parametrize("output", ["screen", "log"])
def test_node_output_passes_through_unchanged(tmp_path: Path, env: dict, output: str) -> None:
    launch = write_launch(tmp_path, NODE.format(output=output))
    result = _roslaunch([ninjemys_bin("roslaunch"), str(launch)], env)
    out, err = result.stdout.splitlines(), result.stderr.splitlines()
    if output == "screen":
        assert ["out line 1", "out line 2"] == [line for line in out if "line" in line], result.stdout
    else:  # stdout goes to the node's log file; stderr still to the screen, as in ROS 1
        assert not [line for line in out if "out line" in line]
        log = next((Path(env["ROS_HOME"]) / "log").glob("*/streams-1-stdout.log"))
        assert log.read_text() == "out line 1\nout line 2\n"
    assert "err line 1" in err, result.stderr
    assert not any("[streams" in line and "line" in line for line in out + err)


@pytest.mark.parametrize("how", ["flag", "env"])
def test_prefixed_output_is_opt_in(tmp_path: Path, env: dict, how: str) -> None:
    launch = write_launch(tmp_path, NODE.format(output="screen"))
    cmd = [ninjemys_bin("roslaunch"), str(launch)]
    if how == "flag":
        cmd.append("--prefix-output")
    else:
        env = dict(env, NINJEMYS_LAUNCH_PREFIX="1")
    result = _roslaunch(cmd, env)
    lines = result.stdout.splitlines()
    for text in ("out line 1", "out line 2", "err line 1"):
        assert f"[streams-1] {text}" in lines, result.stdout


_STARTED = re.compile(r"(\x1b\[1m)?process\[[^\]]*\]: started with pid \[\d+\](\x1b\[0m)?\n?")


@pytest.mark.ros1
@pytest.mark.skipif(not have_ros1(), reason="needs Debian's ROS 1")
def test_real_roslaunch_passes_output_through_too(tmp_path: Path, env: dict) -> None:
    """The reference: Debian's roslaunch gives the very lines ours gives."""
    launch = write_launch(tmp_path, NODE.format(output="screen"))
    real_env = ros1_env(
        env["ROS_MASTER_URI"], ROS_PACKAGE_PATH=env["ROS_PACKAGE_PATH"], ROS_HOME=env["ROS_HOME"]
    )
    real = _roslaunch(["/usr/bin/roslaunch", str(launch)], real_env)
    ours = _roslaunch([ninjemys_bin("roslaunch"), str(launch)], env)
    for result in (real, ours):
        # roslaunch's own "process[...]: started with pid [...]" shares the terminal with the child and,
        # under load, Debian's can land on the same line as the child's first output: not ours to judge
        stdout = _STARTED.sub("", result.stdout)
        assert [line for line in stdout.splitlines() if "line" in line] == ["out line 1", "out line 2"]
        assert "err line 1" in result.stderr.splitlines()

"""rosrun: finds and runs package executables with their arguments; clear one-line errors."""

from __future__ import annotations

import os
import subprocess
from pathlib import Path

import pytest

from ninjemys.testing import ninjemys_bin

PKGS = Path(__file__).parent.parent / "launch" / "data" / "pkgs"


@pytest.fixture
def env(tmp_path: Path) -> dict[str, str]:
    e = dict(os.environ, ROS_PACKAGE_PATH=str(PKGS))
    e.pop("CMAKE_PREFIX_PATH", None)
    return e


def rosrun(*args: str, env: dict[str, str]) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [ninjemys_bin("rosrun"), *args], env=env, capture_output=True, text=True, timeout=60, check=False
    )


def test_runs_script_with_args_and_remaps(env: dict[str, str]) -> None:
    result = rosrun("corpus_run", "crasher.py", "0", "chatter:=/other", "__name:=talker1", env=env)
    assert result.returncode == 3
    assert result.stdout == "crasher running\n"


def test_remapping_args_reach_the_process(tmp_path: Path, env: dict[str, str]) -> None:
    pkg = tmp_path / "echo_pkg"
    (pkg / "scripts").mkdir(parents=True)
    (pkg / "package.xml").write_text(
        '<package format="2"><name>echo_pkg</name><version>1.0.0</version></package>'
    )
    script = pkg / "scripts" / "echo.py"
    script.write_text("#!/usr/bin/env python3\nimport sys\nprint(sys.argv[1:])\n")
    script.chmod(0o755)
    env["ROS_PACKAGE_PATH"] = str(tmp_path)
    result = rosrun("echo_pkg", "echo.py", "a", "chatter:=/x", "_rate:=5", "__name:=n1", env=env)
    assert result.returncode == 0, result.stderr
    assert result.stdout.strip() == "['a', 'chatter:=/x', '_rate:=5', '__name:=n1']"


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (("no_such_pkg", "x"), "[rosrun] package 'no_such_pkg' not found"),
        (("corpus_run", "ghost.py"), "[rosrun] Couldn't find executable named ghost.py"),
        (("corpus_run", "noexec.py"), "chmod +x"),
        (("corpus_run",), "Usage: rosrun"),
    ],
)
def test_errors_are_one_line_without_traceback(
    args: tuple[str, ...], message: str, env: dict[str, str]
) -> None:
    result = rosrun(*args, env=env)
    assert result.returncode != 0
    assert message in result.stderr
    assert "Traceback" not in result.stderr
    assert len(result.stderr.strip().splitlines()) == 1


def test_prefix_option_wraps_command(env: dict[str, str]) -> None:
    result = rosrun("--prefix", "env NJ_PREFIXED=1", "corpus_run", "crasher.py", "0", env=env)
    assert result.returncode == 3
    assert result.stdout == "crasher running\n"

"""rospack, rosversion and rosed command lines."""

from __future__ import annotations

import os
import subprocess
from pathlib import Path

import pytest

from ninjemys.testing import ninjemys_bin

PKGS = Path(__file__).parent.parent / "launch" / "data" / "pkgs"


@pytest.fixture
def env() -> dict[str, str]:
    return dict(os.environ, ROS_PACKAGE_PATH=str(PKGS))


def run(cmd: str, *args: str, env: dict[str, str]) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [ninjemys_bin(cmd), *args], env=env, capture_output=True, text=True, timeout=60, check=False
    )


def test_rospack_find_list_and_errors(env: dict[str, str]) -> None:
    assert run("rospack", "find", "corpus_a", env=env).stdout.strip() == str(PKGS / "corpus_a")
    names = run("rospack", "list-names", env=env).stdout.split()
    assert {"corpus_a", "corpus_b", "std_msgs", "turtlesim"} <= set(names)
    listing = run("rospack", "list", env=env).stdout.splitlines()
    assert f"corpus_b {PKGS / 'corpus_b'}" in listing
    missing = run("rospack", "find", "no_such_pkg", env=env)
    assert missing.returncode == 1
    assert missing.stderr.strip() == "[rospack] Error: package 'no_such_pkg' not found"


def test_rospack_depends(env: dict[str, str]) -> None:
    deps = run("rospack", "depends", "geometry_msgs", env=env).stdout.split()
    assert "std_msgs" in deps
    users = run("rospack", "depends-on1", "std_msgs", env=env).stdout.split()
    assert "geometry_msgs" in users


def test_rosversion(env: dict[str, str]) -> None:
    assert run("rosversion", "corpus_a", env=env).stdout == "0.3.1\n"
    assert run("rosversion", "-d", env=env).stdout == "noetic\n"


def test_rosed_opens_the_file_in_editor(env: dict[str, str]) -> None:
    env["EDITOR"] = "echo editing"
    result = run("rosed", "corpus_b", "animals.launch", env=env)
    assert result.returncode == 0
    assert result.stdout.strip() == f"editing {PKGS / 'corpus_b' / 'launch' / 'animals.launch'}"
    missing = run("rosed", "corpus_b", "nope.launch", env=env)
    assert missing.returncode == 1 and "cannot find file [nope.launch]" in missing.stderr

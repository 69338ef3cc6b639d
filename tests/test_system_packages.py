"""Every Debian ROS package on this machine that someone installed by hand is one `make test`
installs: a test that passes here because of a hand-installed package would fail on a fresh
machine (it happened: the rosmsg parity test needed libdynamic-reconfigure-config-init-mutex-dev).

Packages pulled in as dependencies are marked automatic by apt and are not checked; what counts
as a ROS package is what Debian says (its homepage is on ros.org or in a ROS GitHub organisation)."""

from __future__ import annotations

import re
import shutil
import subprocess
from pathlib import Path

import pytest

MAKEFILE = Path(__file__).resolve().parent.parent / "Makefile"
ROS_HOMEPAGE = re.compile(r"ros\.org|github\.com/(ros|ros-planning|ros-perception|ros-visualization)/", re.I)


def makefile_debs() -> set[str]:
    """The names in the Makefile's *_DEBS variables, `=`, `:=` and `+=` alike (continuation lines joined)."""
    text = MAKEFILE.read_text(encoding="utf-8").replace("\\\n", " ")
    names: set[str] = set()
    for match in re.finditer(r"^[A-Z0-9_]*DEBS\s*[+:]?=(.*)$", text, re.M):
        names.update(word for word in match.group(1).split() if not word.startswith("$("))
    return names


@pytest.mark.skipif(shutil.which("apt-mark") is None, reason="not a Debian machine")
def test_hand_installed_ros_packages_are_installed_by_make_test() -> None:
    manual = subprocess.run(
        ["apt-mark", "showmanual"], capture_output=True, text=True, check=True
    ).stdout.split()
    if not manual:
        pytest.skip("apt-mark lists no manually installed package")
    query = subprocess.run(
        ["dpkg-query", "-W", "-f=${Package}\t${Homepage}\n", *manual],
        capture_output=True,
        text=True,
        check=False,
    ).stdout
    ros = {line.split("\t")[0] for line in query.splitlines() if ROS_HOMEPAGE.search(line)}
    missing = sorted(ros - makefile_debs())
    assert not missing, f"installed by hand but not by `make test` (add them to the Makefile): {missing}"


def test_the_makefile_lists_are_read() -> None:
    debs = makefile_debs()
    assert {"python3-rospy", "chromium", "libdynamic-reconfigure-config-init-mutex-dev"} <= debs

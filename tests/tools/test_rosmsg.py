"""rosmsg / rossrv: ROS 1's output, byte for byte (compared with Debian's /usr/bin/rosmsg)."""

from __future__ import annotations

import os
import subprocess
from pathlib import Path

import pytest

from ninjemys.testing import have_ros1, ninjemys_bin, ros1_built_interfaces, ros1_env


def ours(
    *argv: str, stdin: str | None = None, env: dict[str, str] | None = None
) -> subprocess.CompletedProcess[str]:
    command, *rest = argv
    return subprocess.run(
        [ninjemys_bin(command), *rest],
        capture_output=True,
        text=True,
        timeout=60,
        input=stdin,
        env={**os.environ, **(env or {})},
    )


def theirs(tmp_path: Path, *argv: str) -> subprocess.CompletedProcess[str]:
    """Real rosmsg over our packages as built (with the messages generated from .action files)."""
    command, *rest = argv
    built = ros1_built_interfaces(tmp_path / "ws")
    env = ros1_env("http://localhost:11311", ROS_PACKAGE_PATH=str(built), HOME=str(tmp_path))
    return subprocess.run([f"/usr/bin/{command}", *rest], capture_output=True, text=True, timeout=60, env=env)


SPAWN = "float32 x\nfloat32 y\nfloat32 theta\nstring name\n---\nstring name\n\n"


@pytest.mark.ros1
@pytest.mark.skipif(not have_ros1(), reason="needs Debian's ROS 1")
@pytest.mark.parametrize(
    "argv",
    [
        ("rosmsg", "show", "geometry_msgs/PoseStamped"),
        ("rosmsg", "show", "-r", "turtlesim/Color"),
        ("rosmsg", "info", "visualization_msgs/Marker"),
        ("rosmsg", "md5", "sensor_msgs/Image"),
        ("rosmsg", "md5", "Twist"),
        ("rossrv", "show", "turtlesim/Spawn"),
        ("rossrv", "show", "-r", "rospy_tutorials/AddTwoInts"),
        ("rossrv", "md5", "nav_msgs/GetPlan"),
        ("rosmsg", "list"),
        ("rosmsg", "package", "geometry_msgs"),
        ("rosmsg", "package", "-s", "turtlesim"),
        ("rossrv", "package", "turtlesim"),
        ("rosmsg", "packages"),
        ("rosmsg", "show", "Pose"),
    ],
    ids=" ".join,
)
def test_output_matches_ros1(argv: tuple[str, ...], tmp_path: Path) -> None:
    real = theirs(tmp_path, *argv)
    assert real.returncode == 0, real.stderr
    mine = ours(*argv)
    assert mine.returncode == 0, mine.stderr
    expected = real.stdout
    if argv[1] in ("list", "packages"):
        # Debian's own actionlib under /usr/share is found besides ours and listed twice
        expected = "".join(dict.fromkeys(expected.splitlines(keepends=True)))
    assert mine.stdout == expected


def test_rossrv_show_spawn_has_ros1_format() -> None:
    done = ours("rossrv", "show", "turtlesim/Spawn")
    assert done.returncode == 0 and done.stdout == SPAWN


def test_show_reads_the_type_from_stdin() -> None:
    done = ours("rosmsg", "show", stdin="std_msgs/String\n")
    assert done.stdout == "string data\n\n"


def test_show_of_action_generated_type() -> None:
    done = ours("rosmsg", "show", "actionlib_tutorials/FibonacciGoal")
    assert done.returncode == 0 and done.stdout == "int32 order\n\n"


@pytest.mark.parametrize(
    ("argv", "needle"),
    [
        (("rosmsg", "show", "nope_pkg/Thing"), "Unable to load msg [nope_pkg/Thing]"),
        (("rosmsg", "show", "NoSuchTypeAnywhere"), "Could not find msg 'NoSuchTypeAnywhere'"),
        (("rosmsg", "md5", "nope_pkg/Thing"), "Cannot locate [nope_pkg/Thing]"),
        (("rossrv", "package", "nope_pkg"), "Invalid package"),
    ],
)
def test_errors_are_one_line_without_traceback(argv: tuple[str, ...], needle: str) -> None:
    done = ours(*argv)
    assert done.returncode == 1
    assert done.stderr.startswith("ERROR: ") and needle in done.stderr
    assert "Traceback" not in done.stderr and done.stderr.count("\n") == 1


def test_malformed_user_definition_reports_file_and_line(tmp_path: Path) -> None:
    pkg = tmp_path / "h1_broken_pkg"
    (pkg / "msg").mkdir(parents=True)
    (pkg / "package.xml").write_text("<package><name>h1_broken_pkg</name></package>")
    (pkg / "msg" / "Bad.msg").write_text("int32 x\nint32\n")
    done = ours("rosmsg", "show", "h1_broken_pkg/Bad", env={"ROS_PACKAGE_PATH": str(tmp_path)})
    assert done.returncode == 1
    assert f"{pkg / 'msg' / 'Bad.msg'}:2:" in done.stderr and "Traceback" not in done.stderr


def test_usage_without_command() -> None:
    done = ours("rossrv")
    assert done.returncode == 0 and done.stdout.startswith("rossrv is a command-line tool")


def test_show_from_a_bag(tmp_path: Path) -> None:
    from ninjemys.bag.api import Bag
    from ninjemys.idl.loader import get_message_class
    from ninjemys.rostime import Time

    path = tmp_path / "one.bag"
    with Bag(str(path), "w") as bag:
        bag.write("/pose", get_message_class("geometry_msgs/PoseStamped")(), Time(1))
    done = ours("rosmsg", "show", "-b", str(path), "geometry_msgs/PoseStamped")
    assert done.returncode == 0, done.stderr
    assert done.stdout == ours("rosmsg", "show", "geometry_msgs/PoseStamped").stdout
    raw = ours("rosmsg", "show", "-r", "-b", str(path), "geometry_msgs/PoseStamped")
    assert raw.stdout == get_message_class("geometry_msgs/PoseStamped")._full_text + "\n"

"""catkin_make says what real catkin would stop at or skip (issue 12, item 4): unresolvable message
field types fail the build with file:line, C++ targets are named as not built, and ``catkin_make
install`` writes an install space."""

from __future__ import annotations

from pathlib import Path

import pytest

from ninjemys.errors import DefinitionError
from ninjemys.tools import catkin_create_pkg, catkin_make


@pytest.fixture
def ws(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    root = tmp_path / "catkin_ws"
    (root / "src").mkdir(parents=True)
    monkeypatch.delenv("ROS_PACKAGE_PATH", raising=False)
    monkeypatch.delenv("CMAKE_PREFIX_PATH", raising=False)
    return root


def create(ws: Path, monkeypatch: pytest.MonkeyPatch, *args: str) -> Path:
    monkeypatch.chdir(ws / "src")
    assert catkin_create_pkg.main(list(args)) == 0
    return ws / "src" / args[0]


def make(ws: Path, monkeypatch: pytest.MonkeyPatch, *args: str) -> int:
    monkeypatch.chdir(ws)
    return catkin_make.main(list(args))


def test_the_seeds_time_msg_fails_with_file_line_and_the_fix(
    ws: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The third seed's time_msg.msg writes ``String date`` without std_msgs/."""
    pkg = create(ws, monkeypatch, "package", "std_msgs", "rospy")
    (pkg / "msg").mkdir()
    msg = pkg / "msg" / "time_msg.msg"
    msg.write_text("# the date and the hour, as text\nString date\nString hour\n")
    with pytest.raises(DefinitionError) as info:
        make(ws, monkeypatch)
    assert str(info.value) == (
        f"{msg}:2: package/time_msg: field type 'String' cannot be resolved: package 'package' has no "
        "message 'String' (did you mean 'std_msgs/String'?)"
    )
    assert not (ws / "devel" / "lib" / "python3" / "dist-packages" / "package").exists()
    msg.write_text("std_msgs/String date\nstd_msgs/String hour\n")
    assert make(ws, monkeypatch) == 0


def test_field_types_resolve_across_packages_and_actions(ws: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    base = create(ws, monkeypatch, "base_msgs", "std_msgs")
    (base / "msg").mkdir()
    (base / "msg" / "Point2.msg").write_text("float64 x\nfloat64 y\n")
    (base / "action").mkdir()
    (base / "action" / "Go.action").write_text("Point2 target\n---\nbool ok\n---\nfloat32 left\n")
    user = create(ws, monkeypatch, "user_msgs", "base_msgs", "geometry_msgs")
    (user / "msg").mkdir()
    (user / "msg" / "Path2.msg").write_text(
        "Header header\nbase_msgs/Point2[] points\ngeometry_msgs/Pose pose\nbase_msgs/GoActionGoal last\n"
    )
    (user / "srv").mkdir()
    (user / "srv" / "Plan.srv").write_text("base_msgs/Point2 goal\n---\nPath2 path\n")
    assert make(ws, monkeypatch) == 0
    # the check runs on every build, not only for changed files: removing a used message breaks it
    (base / "msg" / "Point2.msg").unlink()
    with pytest.raises(
        DefinitionError, match=r"Go.action:1: base_msgs/Go: field type 'Point2' cannot be resolved"
    ):
        make(ws, monkeypatch)


def test_unknown_package_in_a_field_type(ws: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    pkg = create(ws, monkeypatch, "p", "std_msgs")
    (pkg / "srv").mkdir()
    srv = pkg / "srv" / "Q.srv"
    srv.write_text("int32 a\n---\nnowhere_msgs/Thing t\n")
    with pytest.raises(DefinitionError) as info:
        make(ws, monkeypatch)
    assert str(info.value).startswith(
        f"{srv}:3: p/Q: field type 'nowhere_msgs/Thing' cannot be resolved: package "
    )


def test_cpp_targets_are_named_as_not_built(ws: Path, monkeypatch: pytest.MonkeyPatch, capsys) -> None:
    pkg = create(ws, monkeypatch, "mixed_pkg", "roscpp", "rospy", "std_msgs")
    cmake = pkg / "CMakeLists.txt"
    text = cmake.read_text()  # catkin_create_pkg's template: its add_executable lines are comments
    lines_before = text.count("\n")
    cmake.write_text(
        text
        + "add_executable(${PROJECT_NAME}_talker src/talker.cpp src/util.cpp)\n"
        + "add_library(helpers STATIC\n  src/helpers.cc)  # a comment (with parentheses)\n"
        + "# add_executable(old src/old.cpp)\n"
    )
    assert make(ws, monkeypatch) == 0
    out = capsys.readouterr().out
    assert "-- ~~  - mixed_pkg: 2 C++ target(s) not built" in out
    assert (
        f"{cmake}:{lines_before + 1}: add_executable(mixed_pkg_talker) (src/talker.cpp, src/util.cpp)" in out
    )
    assert f"{cmake}:{lines_before + 2}: add_library(helpers) (src/helpers.cc)" in out
    assert "src/old.cpp" not in out
    assert "-- 2 C++ target(s) not built (see above): mixed_pkg_talker, helpers" in out


def test_python_only_package_mentions_no_cpp(ws: Path, monkeypatch: pytest.MonkeyPatch, capsys) -> None:
    create(ws, monkeypatch, "py_pkg", "rospy")
    assert make(ws, monkeypatch) == 0
    assert "C++" not in capsys.readouterr().out

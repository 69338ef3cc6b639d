"""catkin_make says what real catkin would stop at or skip (issue 12, item 4): unresolvable message
field types fail the build with file:line, C++ targets are named as not built, and ``catkin_make
install`` writes an install space."""

from __future__ import annotations

import os
import shutil
import subprocess
from pathlib import Path

import pytest

from ninjemys.errors import DefinitionError, PackageError
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
    monkeypatch.setenv("NINJEMYS_CATKIN_CPP", "0")  # as on a machine without the C++ toolchain
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
    assert "[NINJEMYS_CATKIN_CPP=0 asks for the Python-only build]" in out
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


DEMO_CMAKE = """\
cmake_minimum_required(VERSION 3.0.2)
project(demo_pkg)
find_package(catkin REQUIRED COMPONENTS rospy std_msgs message_generation)
catkin_python_setup()
add_message_files(FILES Reading.msg)
add_service_files(FILES Ask.srv)
generate_messages(DEPENDENCIES std_msgs)
catkin_package(CATKIN_DEPENDS message_runtime std_msgs rospy)
catkin_install_python(PROGRAMS scripts/talker.py DESTINATION ${CATKIN_PACKAGE_BIN_DESTINATION})
install(DIRECTORY launch DESTINATION ${CATKIN_PACKAGE_SHARE_DESTINATION})
install(FILES notes.txt DESTINATION ${CATKIN_PACKAGE_SHARE_DESTINATION}/doc)
"""

DEMO_MANIFEST = """\
<?xml version="1.0"?>
<package format="2">
  <name>demo_pkg</name>
  <version>0.1.0</version>
  <description>install space demo</description>
  <maintainer email="dev@example.com">dev</maintainer>
  <license>BSD</license>
  <buildtool_depend>catkin</buildtool_depend>
  <build_depend>message_generation</build_depend>
  <depend>std_msgs</depend>
  <depend>rospy</depend>
  <exec_depend>message_runtime</exec_depend>
</package>
"""

#: what real catkin_make install (Debian's catkin) writes for demo_pkg, less its C++/Lisp/CMake/pkg-config
#: outputs and catkin's own helpers (see _python_relevant)
CATKIN_INSTALL_LAYOUT = {
    "setup.sh",
    "setup.bash",
    "setup.zsh",
    "local_setup.sh",
    "local_setup.bash",
    "local_setup.zsh",
    "lib/demo_pkg/talker.py",
    "lib/python3/dist-packages/demo_pkg/__init__.py",
    "lib/python3/dist-packages/demo_pkg/msg/__init__.py",
    "lib/python3/dist-packages/demo_pkg/srv/__init__.py",
    "share/demo_pkg/package.xml",
    "share/demo_pkg/launch/demo.launch",
    "share/demo_pkg/doc/notes.txt",
    "share/demo_pkg/msg/Reading.msg",
    "share/demo_pkg/srv/Ask.srv",
}


def demo_workspace(root: Path) -> None:
    pkg = root / "src" / "demo_pkg"
    for sub in ("msg", "srv", "scripts", "launch", "src/demo_pkg"):
        (pkg / sub).mkdir(parents=True, exist_ok=True)
    (pkg / "package.xml").write_text(DEMO_MANIFEST)
    (pkg / "CMakeLists.txt").write_text(DEMO_CMAKE)
    (pkg / "setup.py").write_text(
        "from setuptools import setup\nfrom catkin_pkg.python_setup import generate_distutils_setup\n"
        "setup(**generate_distutils_setup(packages=['demo_pkg'], package_dir={'': 'src'}))\n"
    )
    (pkg / "msg" / "Reading.msg").write_text("float32 value\n")
    (pkg / "srv" / "Ask.srv").write_text("string q\n---\nstring a\n")
    talker = pkg / "scripts" / "talker.py"
    talker.write_text('#!/usr/bin/env python3\nprint("talker runs")\n')
    talker.chmod(0o755)
    (pkg / "launch" / "demo.launch").write_text(
        '<launch><node pkg="demo_pkg" type="talker.py" name="t"/></launch>\n'
    )
    (pkg / "notes.txt").write_text("hello\n")
    (pkg / "src" / "demo_pkg" / "__init__.py").write_text("X = 1\n")


def _files(root: Path) -> set[str]:
    return {str(p.relative_to(root)) for p in root.rglob("*") if p.is_file() and "__pycache__" not in p.parts}


def _python_relevant(path: str) -> bool:
    """Real catkin's install outputs that a pure-Python build has a counterpart for."""
    skipped = ("include/", "share/common-lisp/", "lib/pkgconfig/", "share/demo_pkg/cmake/")
    helpers = {".catkin", ".rosinstall", "_setup_util.py", "env.sh"}
    name = path.rsplit("/", 1)[-1]
    return not (
        path.startswith(skipped)
        or path in helpers
        or ".egg-info/" in path
        or name.startswith("_")
        and name != "__init__.py"
    )


def test_install_space_works_without_the_sources(ws: Path, monkeypatch: pytest.MonkeyPatch, capsys) -> None:
    demo_workspace(ws)
    assert make(ws, monkeypatch, "install") == 0
    out = capsys.readouterr().out
    install = ws / "install"
    assert f"-- Installing: {install / 'lib' / 'demo_pkg' / 'talker.py'}" in out
    assert _files(install) - {".ninjemys_devel"} == CATKIN_INSTALL_LAYOUT
    assert os.access(install / "lib" / "demo_pkg" / "talker.py", os.X_OK)
    # a second run changes nothing
    assert make(ws, monkeypatch, "install") == 0
    assert "-- Installing:" not in capsys.readouterr().out
    # the install space stands alone: move the sources and devel away, source it, use everything
    (ws / "src").rename(ws / "src.away")
    shutil.rmtree(ws / "devel")
    script = (
        "source install/setup.bash && rospack find demo_pkg && "
        "python3 -c 'import demo_pkg; from demo_pkg.msg import Reading; from demo_pkg.srv import Ask; "
        "print(demo_pkg.X, Reading(value=1.5).value, Ask._type)' && rosrun demo_pkg talker.py && "
        "roslaunch demo_pkg demo.launch --nodes"
    )
    env = {"PATH": "/usr/bin:/bin", "HOME": str(ws)}
    result = subprocess.run(
        ["bash", "-c", script], cwd=ws, env=env, capture_output=True, text=True, timeout=60
    )
    assert result.returncode == 0, result.stderr
    assert result.stdout.splitlines() == [
        str(install / "share" / "demo_pkg"),
        "1 1.5 demo_pkg/Ask",
        "talker runs",
        "/t",
    ]


def test_install_names_an_uninstalled_launch_dir_and_a_missing_file(
    ws: Path, monkeypatch: pytest.MonkeyPatch, capsys
) -> None:
    demo_workspace(ws)
    cmake = ws / "src" / "demo_pkg" / "CMakeLists.txt"
    cmake.write_text(
        DEMO_CMAKE.replace("install(DIRECTORY launch DESTINATION ${CATKIN_PACKAGE_SHARE_DESTINATION})\n", "")
    )
    assert make(ws, monkeypatch, "install", "-DCMAKE_INSTALL_PREFIX=elsewhere") == 0
    assert "-- demo_pkg: launch/ is not installed: no install(DIRECTORY launch" in capsys.readouterr().out
    assert (ws / "elsewhere" / "setup.bash").is_file() and not (
        ws / "elsewhere" / "share" / "demo_pkg" / "launch"
    ).exists()
    (ws / "src" / "demo_pkg" / "notes.txt").unlink()
    with pytest.raises(PackageError, match=rf"{cmake}:10: install\(FILES notes.txt\) names a missing file"):
        make(ws, monkeypatch, "install")


@pytest.mark.ros1
@pytest.mark.slow
@pytest.mark.skipif(
    shutil.which("cmake") is None or not Path("/usr/bin/catkin_make").exists(), reason="needs Debian's catkin"
)
def test_layout_matches_real_catkin_make_install(tmp_path: Path) -> None:
    real = tmp_path / "real_ws"
    demo_workspace(real)
    env = {"PATH": "/usr/bin:/bin", "HOME": str(tmp_path)}
    result = subprocess.run(
        ["/usr/bin/catkin_make", "install"], cwd=real, env=env, capture_output=True, text=True, timeout=600
    )
    assert result.returncode == 0, result.stdout[-2000:] + result.stderr[-2000:]
    assert {p for p in _files(real / "install") if _python_relevant(p)} == CATKIN_INSTALL_LAYOUT

"""catkin_create_pkg / catkin_init_workspace / catkin_make: files, stubs, relays, incrementality, errors."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

from ninjemys.errors import DefinitionError, PackageError
from ninjemys.packages.builder import STUB
from ninjemys.packages.manifest import parse_manifest
from ninjemys.tools import catkin_create_pkg, catkin_init_workspace, catkin_make


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


def test_create_pkg_writes_usable_package(ws: Path, monkeypatch: pytest.MonkeyPatch, capsys) -> None:
    pkg = create(ws, monkeypatch, "first_pkg", "std_msgs", "rospy", "roscpp")
    out = capsys.readouterr().out
    assert "Created file first_pkg/package.xml" in out
    manifest = parse_manifest(pkg / "package.xml")
    assert manifest.format == 2
    assert manifest.build_depends == ("std_msgs", "rospy", "roscpp")
    assert manifest.exec_depends == ("std_msgs", "rospy", "roscpp")
    assert manifest.buildtool_depends == ("catkin",)
    cmake = (pkg / "CMakeLists.txt").read_text()
    assert "project(first_pkg)" in cmake and "find_package(catkin REQUIRED COMPONENTS" in cmake
    assert (pkg / "src").is_dir() and (pkg / "include" / "first_pkg").is_dir()


def test_create_pkg_refuses_existing_and_bad_names(ws: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    create(ws, monkeypatch, "dup")
    with pytest.raises(PackageError, match="File exists"):
        catkin_create_pkg.main(["dup"])
    with pytest.raises(PackageError, match="invalid package name"):
        catkin_create_pkg.main(["Bad-Name"])


def test_init_workspace(ws: Path) -> None:
    assert catkin_init_workspace.main([str(ws / "src")]) == 0
    assert "catkin_workspace()" in (ws / "src" / "CMakeLists.txt").read_text()
    with pytest.raises(PackageError, match="already exists"):
        catkin_init_workspace.main([str(ws / "src")])


def test_make_generates_stubs_setup_and_is_incremental(
    ws: Path, monkeypatch: pytest.MonkeyPatch, capsys
) -> None:
    pkg = create(ws, monkeypatch, "chat_pkg", "std_msgs", "rospy")
    (pkg / "msg").mkdir()
    (pkg / "msg" / "Reading.msg").write_text("Header header\nfloat32 value\n")
    (pkg / "srv").mkdir()
    (pkg / "srv" / "Ask.srv").write_text("string q\n---\nstring a\n")
    assert make(ws, monkeypatch) == 0
    dist = ws / "devel" / "lib" / "python3" / "dist-packages" / "chat_pkg"
    assert (dist / "msg" / "__init__.py").read_text() == STUB
    assert (dist / "srv" / "__init__.py").read_text() == STUB
    for name in ("setup.bash", "setup.sh", "setup.zsh"):
        assert (ws / "devel" / name).is_file()
    assert (ws / "src" / "CMakeLists.txt").is_file()
    capsys.readouterr()
    assert make(ws, monkeypatch) == 0
    assert "0 file(s) updated, 0 definition(s) checked" in capsys.readouterr().out
    (pkg / "srv" / "Ask.srv").unlink()
    assert make(ws, monkeypatch) == 0
    assert not (dist / "srv").exists()


def test_message_class_importable_after_make(ws: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    pkg = create(ws, monkeypatch, "custom_msgs", "std_msgs")
    (pkg / "msg").mkdir()
    (pkg / "msg" / "Stamped.msg").write_text("Header header\nfloat32 data\n")
    assert make(ws, monkeypatch) == 0
    env = dict(os.environ)
    env["ROS_PACKAGE_PATH"] = str(ws / "src")
    env["PYTHONPATH"] = str(ws / "devel" / "lib" / "python3" / "dist-packages")
    code = "from custom_msgs.msg import Stamped; m = Stamped(); m.data = 2.5; print(Stamped._type, m.data)"
    result = subprocess.run(
        [sys.executable, "-c", code], env=env, capture_output=True, text=True, check=False
    )
    assert result.returncode == 0, result.stderr
    assert result.stdout.strip() == "custom_msgs/Stamped 2.5"


def test_python_setup_and_install_python_relays(ws: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    pkg = create(ws, monkeypatch, "pylib", "rospy")
    (pkg / "src" / "pylib").mkdir(parents=True)
    (pkg / "src" / "pylib" / "__init__.py").write_text("ANSWER = 42\n")
    (pkg / "src" / "pylib" / "util.py").write_text("def twice(x):\n    return 2 * x\n")
    (pkg / "setup.py").write_text(
        "from setuptools import setup\nfrom catkin_pkg.python_setup import generate_distutils_setup\n"
        "setup(**generate_distutils_setup(packages=['pylib'], package_dir={'': 'src'}))\n"
    )
    (pkg / "msg").mkdir()
    (pkg / "msg" / "Note.msg").write_text("string text\n")
    (pkg / "scripts").mkdir()
    (pkg / "scripts" / "tool.py").write_text("import sys\nprint('tool', sys.argv[1:])\n")
    cmake = (pkg / "CMakeLists.txt").read_text().replace("# catkin_python_setup()", "catkin_python_setup()")
    cmake += (
        "\ncatkin_install_python(PROGRAMS scripts/tool.py\n  DESTINATION ${CATKIN_PACKAGE_BIN_DESTINATION})\n"
    )
    (pkg / "CMakeLists.txt").write_text(cmake)
    assert make(ws, monkeypatch) == 0
    env = dict(os.environ, ROS_PACKAGE_PATH=str(ws / "src"))
    env["PYTHONPATH"] = str(ws / "devel" / "lib" / "python3" / "dist-packages")
    code = "import pylib, pylib.util; from pylib.msg import Note; print(pylib.ANSWER, pylib.util.twice(4), Note._type)"
    result = subprocess.run(
        [sys.executable, "-c", code], env=env, capture_output=True, text=True, check=False
    )
    assert result.returncode == 0, result.stderr
    assert result.stdout.split() == ["42", "8", "pylib/Note"]
    relay = ws / "devel" / "lib" / "pylib" / "tool.py"
    assert os.access(relay, os.X_OK)
    result = subprocess.run([str(relay), "x"], capture_output=True, text=True, check=False)
    assert result.stdout.strip() == "tool ['x']"


def test_duplicate_package_names_are_an_error(ws: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    create(ws, monkeypatch, "twin")
    (ws / "src" / "other").mkdir()
    (ws / "src" / "other" / "package.xml").write_text((ws / "src" / "twin" / "package.xml").read_text())
    with pytest.raises(PackageError, match="two packages are named 'twin'"):
        make(ws, monkeypatch)


def test_malformed_package_xml_names_file_and_line(ws: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    pkg = create(ws, monkeypatch, "broken")
    (pkg / "package.xml").write_text('<package format="2">\n<name>broken</name>\n<oops>\n</package>\n')
    with pytest.raises(PackageError, match=r"package.xml:4: malformed package.xml"):
        make(ws, monkeypatch)


def test_missing_dependency_is_named(ws: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    create(ws, monkeypatch, "needy", "rospy", "nonexistent_msgs")  # find_package(catkin ... COMPONENTS)
    with pytest.raises(PackageError, match="Could not find a package configuration file provided by") as info:
        make(ws, monkeypatch)
    assert "needy/CMakeLists.txt:" in str(info.value)
    assert "ninjemys: 'nonexistent_msgs' (required by needy)" in str(info.value)


def test_malformed_msg_fails_build_with_file_and_line(ws: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    pkg = create(ws, monkeypatch, "badmsg", "std_msgs")
    (pkg / "msg").mkdir()
    (pkg / "msg" / "Bad.msg").write_text("float32 ok\nthis is wrong\n")
    with pytest.raises(DefinitionError) as err:
        make(ws, monkeypatch)
    assert "Bad.msg:2:" in str(err.value)
    assert not (ws / "devel" / "lib" / "python3" / "dist-packages" / "badmsg").exists()


def test_seed_cmake_and_package_edits_are_accepted(ws: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    pkg = create(ws, monkeypatch, "edited", "std_msgs", "rospy")
    (pkg / "msg").mkdir()
    (pkg / "msg" / "Num.msg").write_text("int64 num\n")
    xml = (
        (pkg / "package.xml")
        .read_text()
        .replace(
            "<buildtool_depend>catkin</buildtool_depend>",
            "<buildtool_depend>catkin</buildtool_depend>\n  <build_depend>message_generation</build_depend>\n"
            "  <exec_depend>message_runtime</exec_depend>",
        )
    )
    (pkg / "package.xml").write_text(xml)
    cmake = (pkg / "CMakeLists.txt").read_text()
    cmake = cmake.replace("  rospy\n", "  rospy\n  message_generation\n")
    cmake += "add_message_files(FILES Num.msg)\ngenerate_messages(DEPENDENCIES std_msgs)\n"
    (pkg / "CMakeLists.txt").write_text(cmake)
    assert make(ws, monkeypatch) == 0
    assert (ws / "devel" / "lib" / "python3" / "dist-packages" / "edited" / "msg" / "__init__.py").exists()


def test_setup_bash_sets_environment_and_shell_functions(ws: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    create(ws, monkeypatch, "shell_pkg", "rospy")
    assert make(ws, monkeypatch) == 0
    script = (
        f"source {ws / 'devel' / 'setup.bash'} && source {ws / 'devel' / 'setup.bash'} && "
        'echo "$ROS_PACKAGE_PATH|$PYTHONPATH|$CMAKE_PREFIX_PATH|$ROS_MASTER_URI" && '
        "roscd shell_pkg && pwd && rosls shell_pkg && type rosrun >/dev/null && echo ok"
    )
    env = {
        k: v
        for k, v in os.environ.items()
        if k not in ("ROS_PACKAGE_PATH", "PYTHONPATH", "CMAKE_PREFIX_PATH")
    }
    env["PATH"] = "/usr/bin:/bin"
    result = subprocess.run(["bash", "-c", script], env=env, capture_output=True, text=True, check=False)
    assert result.returncode == 0, result.stderr
    lines = result.stdout.splitlines()
    rpp, pythonpath, prefix, master = lines[0].split("|")
    assert rpp == str(ws / "src")
    assert pythonpath == str(ws / "devel" / "lib" / "python3" / "dist-packages")
    assert prefix == str(ws / "devel")
    assert master == "http://localhost:11311"
    assert lines[1] == str(ws / "src" / "shell_pkg")
    assert "package.xml" in lines
    assert lines[-1] == "ok"


def test_workspaces_chain(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delenv("ROS_PACKAGE_PATH", raising=False)
    monkeypatch.delenv("CMAKE_PREFIX_PATH", raising=False)
    under = tmp_path / "under_ws"
    over = tmp_path / "over_ws"
    for root in (under, over):
        (root / "src").mkdir(parents=True)
    create(under, monkeypatch, "base_pkg")
    assert make(under, monkeypatch) == 0
    monkeypatch.setenv("CMAKE_PREFIX_PATH", str(under / "devel"))
    create(over, monkeypatch, "top_pkg", "base_pkg")
    assert make(over, monkeypatch) == 0
    env = {k: v for k, v in os.environ.items() if k not in ("ROS_PACKAGE_PATH", "CMAKE_PREFIX_PATH")}
    result = subprocess.run(
        [
            "bash",
            "-c",
            f"source {over / 'devel' / 'setup.bash'} && echo $ROS_PACKAGE_PATH && rospack find base_pkg",
        ],
        env=env,
        capture_output=True,
        text=True,
        check=False,
    )
    assert result.returncode == 0, result.stderr
    first, found = result.stdout.splitlines()
    assert first == f"{over / 'src'}:{under / 'src'}"
    assert found == str(under / "src" / "base_pkg")


def test_setup_bash_completes_packages_launch_files_and_executables(
    ws: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    pkg = create(ws, monkeypatch, "comp_pkg", "rospy")
    (pkg / "launch").mkdir()
    (pkg / "launch" / "demo.launch").write_text("<launch/>")
    (pkg / "scripts").mkdir()
    (pkg / "scripts" / "node.py").write_text("print(1)\n")
    (pkg / "scripts" / "node.py").chmod(0o755)
    assert make(ws, monkeypatch) == 0
    script = (
        f"source {ws / 'devel' / 'setup.bash'}\n"
        'COMP_WORDS=(roscd comp_); COMP_CWORD=1; _roscd; echo "${COMPREPLY[*]}"\n'
        'COMP_WORDS=(roslaunch comp_pkg ""); COMP_CWORD=2; _roslaunch; echo "${COMPREPLY[*]}"\n'
        'COMP_WORDS=(rosrun comp_pkg ""); COMP_CWORD=2; _rosrun; echo "${COMPREPLY[*]}"\n'
    )
    env = {k: v for k, v in os.environ.items() if k not in ("ROS_PACKAGE_PATH", "CMAKE_PREFIX_PATH")}
    result = subprocess.run(["bash", "-c", script], env=env, capture_output=True, text=True, check=False)
    assert result.stdout.splitlines() == ["comp_pkg", "demo.launch", "node.py"], result.stderr

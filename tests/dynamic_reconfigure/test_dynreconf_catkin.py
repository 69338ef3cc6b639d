"""catkin_make generates <pkg>.cfg.<Name>Config from cfg/*.cfg with no CMake edit; errors say file:line."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest
from dyn_fixtures import TUTORIAL_CFG

from ninjemys.errors import DefinitionError
from ninjemys.testing import CatkinWorkspace
from ninjemys.tools import catkin_make

MANIFEST = """<?xml version="1.0"?>
<package format="2">
  <name>dyn_demo</name>
  <version>0.0.1</version>
  <description>dynamic_reconfigure demo</description>
  <maintainer email="a@b.c">a</maintainer>
  <license>BSD</license>
  <buildtool_depend>catkin</buildtool_depend>
  <depend>rospy</depend>
  <depend>dynamic_reconfigure</depend>
</package>
"""

CMAKE = "cmake_minimum_required(VERSION 3.0.2)\nproject(dyn_demo)\nfind_package(catkin REQUIRED)\ncatkin_package()\n"


@pytest.fixture
def ws(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    monkeypatch.delenv("ROS_PACKAGE_PATH", raising=False)
    monkeypatch.delenv("CMAKE_PREFIX_PATH", raising=False)
    CatkinWorkspace(tmp_path / "ws").package(
        "dyn_demo", {"package.xml": MANIFEST, "CMakeLists.txt": CMAKE, "cfg/Tutorials.cfg": TUTORIAL_CFG}
    )
    monkeypatch.chdir(tmp_path / "ws")
    return tmp_path / "ws"


def test_cfg_generates_importable_config(ws: Path) -> None:
    assert catkin_make.main([]) == 0
    generated = ws / "devel" / "lib" / "python3" / "dist-packages" / "dyn_demo" / "cfg" / "TutorialsConfig.py"
    assert generated.is_file()
    script = (
        f"source {ws / 'devel' / 'setup.bash'} && {sys.executable} -c "
        "'from dyn_demo.cfg import TutorialsConfig as T; print(T.defaults[\"int_param\"], T.Tutorials_Large)'"
    )
    out = subprocess.run(["bash", "-c", script], capture_output=True, text=True, timeout=60)
    assert out.stdout.split() == ["50", "2"], out.stderr
    # a removed .cfg takes its module with it on the next build
    (ws / "src" / "dyn_demo" / "cfg" / "Tutorials.cfg").unlink()
    assert catkin_make.main([]) == 0
    assert not generated.exists()


def test_install_space_carries_the_config_modules(ws: Path) -> None:
    """As generate_dynamic_reconfigure_options installs them: <pkg>/cfg/ in dist-packages, importable
    from install/setup.bash once the sources and devel/ are gone."""
    assert catkin_make.main(["install"]) == 0
    dist = ws / "install" / "lib" / "python3" / "dist-packages" / "dyn_demo"
    # Debian's catkin_make install writes these (plus .pyc, the C++ header and pkg-config file)
    written = {str(p.relative_to(dist)) for p in dist.rglob("*") if p.is_file()}
    assert written == {"__init__.py", "cfg/__init__.py", "cfg/TutorialsConfig.py"}
    assert (dist / "__init__.py").read_text() == ""
    for gone in ("src", "devel", "build"):
        (ws / gone).rename(ws.parent / f"{gone}.moved")
    script = (
        f"source {ws / 'install' / 'setup.bash'} && {sys.executable} -c "
        "'from dyn_demo.cfg import TutorialsConfig as T; print(T.defaults[\"int_param\"], T.__file__)'"
    )
    out = subprocess.run(["bash", "-c", script], capture_output=True, text=True, timeout=60)
    assert out.stdout.split() == ["50", str(dist / "cfg" / "TutorialsConfig.py")], out.stderr


def test_cfg_error_fails_build_with_file_line(ws: Path) -> None:
    cfg = ws / "src" / "dyn_demo" / "cfg" / "Tutorials.cfg"
    cfg.write_text(
        TUTORIAL_CFG.replace('"A double parameter", .5, 0, 1)', '"A double parameter", "half", 0, 1)')
    )
    with pytest.raises(DefinitionError) as info:
        catkin_make.main([])
    assert str(info.value) == f"{cfg}:9: 'double_param' has type double, but default is 'half'"


def test_catkin_make_console_reports_cfg_error(ws: Path) -> None:
    cfg = ws / "src" / "dyn_demo" / "cfg" / "Tutorials.cfg"
    cfg.write_text(TUTORIAL_CFG.replace('gen.add("bool_param", bool_t', 'gen.add("bool param", bool_t'))
    from ninjemys.commands import command_path

    out = subprocess.run([command_path("catkin_make")], capture_output=True, text=True, timeout=60, cwd=ws)
    assert out.returncode == 1
    assert (
        f"ERROR: {cfg}:11: The name of field 'bool param' does not follow the ROS naming conventions"
        in out.stderr
    )
    assert "-- ~~  - dyn_demo" in out.stdout

"""Finding executables for rosrun/roslaunch: package files, devel relays, shipped modules."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

from ninjemys.errors import PackageError
from ninjemys.packages.discovery import PackageIndex
from ninjemys.packages.executables import find_executable
from ninjemys.packages.manifest import parse_manifest
from ninjemys.packages.shipped import SHIPPED, shipped_executable


def make_pkg(tmp_path: Path) -> Path:
    pkg = tmp_path / "pkg"
    (pkg / "scripts").mkdir(parents=True)
    (pkg / "package.xml").write_text('<package format="2"><name>pkg</name><version>1.0.0</version></package>')
    return pkg


def script(path: Path, executable: bool = True) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text("#!/usr/bin/env python3\nimport sys\nprint('ran', sys.argv[1:])\n")
    path.chmod(0o755 if executable else 0o644)
    return path


def test_python_script_runs_under_our_interpreter(tmp_path: Path) -> None:
    pkg = make_pkg(tmp_path)
    target = script(pkg / "scripts" / "talker.py")
    exe = find_executable(parse_manifest(pkg / "package.xml"), "talker.py", env={})
    assert exe.path == target
    assert exe.command(["a:=b"]) == [sys.executable, str(target), "a:=b"]


def test_not_executable_gives_chmod_hint(tmp_path: Path) -> None:
    pkg = make_pkg(tmp_path)
    target = script(pkg / "scripts" / "listener.py", executable=False)
    with pytest.raises(PackageError, match=r"chmod \+x") as err:
        find_executable(parse_manifest(pkg / "package.xml"), "listener.py", env={})
    assert str(target) in str(err.value)


def test_devel_lib_wins_over_sources(tmp_path: Path) -> None:
    pkg = make_pkg(tmp_path)
    script(pkg / "scripts" / "node")
    devel = tmp_path / "devel"
    relay = script(devel / "lib" / "pkg" / "node")
    exe = find_executable(parse_manifest(pkg / "package.xml"), "node", env={"CMAKE_PREFIX_PATH": str(devel)})
    assert exe.path == relay


def test_missing_executable_error(tmp_path: Path) -> None:
    pkg = make_pkg(tmp_path)
    with pytest.raises(PackageError, match="Couldn't find executable named ghost"):
        find_executable(parse_manifest(pkg / "package.xml"), "ghost", env={})


def test_shipped_table_has_the_fixed_names() -> None:
    assert shipped_executable("turtlesim", "turtlesim_node").target == "ninjemys.web.turtlesim_view:main"
    assert shipped_executable("turtlesim", "turtle_teleop_key").target == "ninjemys.sim.teleop_key:main"
    assert shipped_executable("rqt_graph", "rqt_graph").target == "ninjemys.web.rqt_graph:main"
    assert shipped_executable("rospy_tutorials", "talker.py").target == "ninjemys.tutorials.talker:main"
    assert shipped_executable("rosout", "rosout").target == "ninjemys.tools.rosout:main"
    assert shipped_executable("rosbag", "record").prefix_args == ("record",)
    assert set(SHIPPED["rospy_tutorials"]) >= {
        "talker",
        "listener",
        "add_two_ints_server",
        "add_two_ints_client",
    }


def test_shipped_executable_resolves_through_package_index() -> None:
    manifest = PackageIndex.from_environment({}).find("turtlesim")
    exe = find_executable(manifest, "turtlesim_node", env={})
    assert exe.shipped is not None
    assert exe.command(["__name:=t"])[-3:] == ["turtlesim", "turtlesim_node", "__name:=t"]


def test_turtlesims_multisim_launch_is_shipped(
    capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    """``roslaunch turtlesim multisim.launch`` (turtlesim's own launch file, used by the tutorials) starts
    two simulators, one per namespace, as on ROS 1; it was "neither a launch file in package [turtlesim]"."""
    from ninjemys.launch.xml import load_launch
    from ninjemys.tools import roslaunch

    monkeypatch.delenv("ROS_PACKAGE_PATH", raising=False)
    assert roslaunch.main(["--nodes", "turtlesim", "multisim.launch"]) == 0
    assert capsys.readouterr().out.split() == ["/turtlesim1/sim", "/turtlesim2/sim"]
    launch = PackageIndex.from_environment({}).find("turtlesim").path / "launch" / "multisim.launch"
    nodes = load_launch([launch], env={}).nodes
    assert {(n.package, n.type) for n in nodes} == {("turtlesim", "turtlesim_node")}


def test_missing_shipped_module_is_one_clear_error(monkeypatch: pytest.MonkeyPatch) -> None:
    from ninjemys.packages import shipped

    fake = shipped.ShippedExecutable("turtlesim", "ghost_node", "ninjemys.sim.no_such_module:main")
    monkeypatch.setitem(shipped.SHIPPED["turtlesim"], "ghost_node", fake)
    from ninjemys.packages import run_shipped

    assert run_shipped.main(["turtlesim", "ghost_node"]) == 1
    result = subprocess.run(
        [sys.executable, "-m", "ninjemys.packages.run_shipped", "turtlesim", "no_such_exe"],
        capture_output=True,
        text=True,
        check=False,
    )
    assert result.returncode == 1
    assert result.stderr.strip() == "ERROR: ninjemys ships no executable [no_such_exe] in package [turtlesim]"

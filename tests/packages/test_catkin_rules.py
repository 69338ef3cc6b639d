"""catkin_make fails exactly where catkin 0.8 fails: on a find_package(... REQUIRED ...) that finds
nothing, never on a dependency named only in package.xml; the libraries ninjemys provides are known
packages; catkin_install_python's DESTINATION is honoured in the devel space.

The ``ros1`` test builds the same workspaces with Debian's real catkin_make (CMake + catkin's macros)
and checks the same pass/fail and the same CMake error text."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from ninjemys.errors import PackageError
from ninjemys.packages.cmake_hints import read_cmake_hints
from ninjemys.packages.discovery import PackageIndex
from ninjemys.packages.workspace import cmake_config_found
from ninjemys.tools import catkin_create_pkg, catkin_make

VENV_BIN = Path(sys.executable).parent

#: libraries ninjemys provides in Python: each must be a package rospack lists and catkin finds
PROVIDED_LIBRARIES = (
    "tf2",
    "tf2_ros",
    "tf2_py",
    "tf_conversions",
    "python_orocos_kdl",
    "tf2_geometry_msgs",
    "tf2_msgs",
    "tf",
    "cv_bridge",
    "laser_geometry",
    "message_filters",
    "actionlib",
    "dynamic_reconfigure",
    "rospy",
    "genpy",
    "rosgraph",
    "roslib",
    "rostopic",
    "rosbag",
    "roslaunch",
    "catkin",
)


def _package(root: Path, name: str, depends: str, cmake: str) -> Path:
    pkg = root / "src" / name
    pkg.mkdir(parents=True)
    (pkg / "package.xml").write_text(
        '<?xml version="1.0"?>\n<package format="2">\n'
        f"  <name>{name}</name>\n  <version>0.0.1</version>\n  <description>test</description>\n"
        '  <maintainer email="dev@example.com">dev</maintainer>\n  <license>BSD</license>\n'
        f"  <buildtool_depend>catkin</buildtool_depend>\n{depends}</package>\n"
    )
    (pkg / "CMakeLists.txt").write_text(
        f"cmake_minimum_required(VERSION 3.0.2)\nproject({name})\n{cmake}catkin_package()\n"
    )
    return pkg


#: package.xml names packages nobody has (a C++ tutorial as test_depend, like rospy_tutorials; an
#: exec_depend installed later): catkin builds it all the same
LOOSE_XML = (
    "  <depend>rospy</depend>\n  <test_depend>roscpp_tutorials</test_depend>\n"
    "  <exec_depend>some_robot_driver</exec_depend>\n  <depend>std_msgs</depend>\n"
)
LOOSE_CMAKE = "find_package(catkin REQUIRED COMPONENTS rospy std_msgs)\n"
#: CMakeLists.txt requires a package nobody has: catkin fails at that line
MISSING_CMAKE = "find_package(catkin REQUIRED COMPONENTS\n  rospy\n  nosuch_pkg\n)\n"


@pytest.fixture
def clean_env(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delenv("ROS_PACKAGE_PATH", raising=False)
    monkeypatch.delenv("CMAKE_PREFIX_PATH", raising=False)


def _make(ws: Path, monkeypatch: pytest.MonkeyPatch) -> int:
    monkeypatch.chdir(ws)
    return catkin_make.main([])


def test_package_xml_dependencies_never_fail_the_build(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, clean_env: None
) -> None:
    _package(tmp_path, "loose", LOOSE_XML, LOOSE_CMAKE)
    assert _make(tmp_path, monkeypatch) == 0


def test_a_required_component_nobody_has_fails_with_cmakes_text_and_one_hint(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, clean_env: None
) -> None:
    _package(tmp_path, "needy", "  <depend>rospy</depend>\n", MISSING_CMAKE)
    with pytest.raises(PackageError) as info:
        _make(tmp_path, monkeypatch)
    text = str(info.value)
    assert text.startswith("CMake Error at /usr/share/catkin/cmake/catkinConfig.cmake:82 (find_package):")
    assert "nosuch_pkgConfig.cmake" in text and "nosuch_pkg-config.cmake" in text
    assert "needy/CMakeLists.txt:3 (find_package)" in text
    assert sum(line.startswith("ninjemys:") for line in text.splitlines()) == 1


def test_a_plain_find_package_of_a_ros_name_fails_at_its_own_line(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, clean_env: None
) -> None:
    _package(tmp_path, "plain", "", "find_package(catkin REQUIRED)\n\nfind_package(nosuch_lib REQUIRED)\n")
    with pytest.raises(PackageError, match=r"CMake Error at plain/CMakeLists.txt:5 \(find_package\)"):
        _make(tmp_path, monkeypatch)


@pytest.mark.parametrize("library", ["NoSuchSystemLib42", "gazebo"])
def test_a_missing_system_library_is_a_note_not_a_failure(
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    clean_env: None,
    capsys: pytest.CaptureFixture[str],
    library: str,
) -> None:
    """gazebo too: a robot's world package finds it for C++ plugins it may not even build."""
    if library == "gazebo" and cmake_config_found("gazebo"):
        pytest.skip("Gazebo's development files are installed here")
    _package(tmp_path, "mixed", "", f"find_package(catkin REQUIRED)\nfind_package({library} REQUIRED)\n")
    assert _make(tmp_path, monkeypatch) == 0
    assert f"find_package({library} REQUIRED) names a system library" in capsys.readouterr().out


@pytest.mark.parametrize("library", PROVIDED_LIBRARIES)
def test_provided_libraries_are_known_packages(library: str) -> None:
    assert library in PackageIndex.from_environment({}).packages


def test_create_pkg_with_cv_bridge_and_tf2_then_make(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, clean_env: None
) -> None:
    (tmp_path / "src").mkdir()
    monkeypatch.chdir(tmp_path / "src")
    assert catkin_create_pkg.main(["p", "rospy", "cv_bridge", "tf2", "tf2_ros", "tf2_geometry_msgs"]) == 0
    assert _make(tmp_path, monkeypatch) == 0


def test_rospack_lists_the_provided_libraries() -> None:
    out = subprocess.run(
        [str(VENV_BIN / "rospack"), "list-names"], capture_output=True, text=True, check=True
    ).stdout.split()
    assert set(PROVIDED_LIBRARIES) <= set(out)


def test_find_package_forms_are_read() -> None:
    hints = _hints(
        "find_package(catkin REQUIRED rospy)\n"
        "find_package(catkin REQUIRED COMPONENTS ${DEPS} std_msgs OPTIONAL_COMPONENTS opt)\n"
        "find_package(Boost REQUIRED COMPONENTS system)\n"
        "find_package(OpenCV)  # not REQUIRED: never fails\n"
        "# find_package(commented REQUIRED)\n"
    )
    assert [(r.name, r.line, r.catkin) for r in hints.required] == [
        ("rospy", 1, True),
        ("std_msgs", 2, True),
        ("Boost", 3, False),
    ]


def _hints(cmake: str):  # noqa: ANN202 - test helper
    import tempfile

    with tempfile.TemporaryDirectory() as d:
        Path(d, "CMakeLists.txt").write_text(cmake)
        return read_cmake_hints(Path(d))


def test_install_python_destination_share_is_a_relay_rosrun_finds(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, clean_env: None
) -> None:
    pkg = _package(
        tmp_path,
        "dest",
        "  <depend>rospy</depend>\n",
        "find_package(catkin REQUIRED COMPONENTS rospy)\n"
        "catkin_install_python(PROGRAMS nodes/tool.py\n"
        "  DESTINATION ${CATKIN_PACKAGE_SHARE_DESTINATION}/nodes)\n",
    )
    (pkg / "nodes").mkdir()
    (pkg / "nodes" / "tool.py").write_text("import sys\nprint('tool ran', sys.argv[1:])\n")
    assert _make(tmp_path, monkeypatch) == 0
    relay = tmp_path / "devel" / "share" / "dest" / "nodes" / "tool.py"
    assert relay.is_file() and os.access(relay, os.X_OK)
    assert not (tmp_path / "devel" / "lib" / "dest" / "tool.py").exists()
    env = dict(os.environ, ROS_PACKAGE_PATH=str(tmp_path / "src"), CMAKE_PREFIX_PATH=str(tmp_path / "devel"))
    result = subprocess.run(
        [str(VENV_BIN / "rosrun"), "dest", "tool.py", "x"],
        env=env,
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert result.stdout.strip() == "tool ran ['x']", result.stderr


def _debian_catkin_make(ws: Path) -> subprocess.CompletedProcess[str]:
    env = {"PATH": "/usr/bin:/bin", "HOME": str(ws), "LANG": "C.UTF-8"}
    return subprocess.run(
        ["/usr/bin/catkin_make"], cwd=ws, env=env, capture_output=True, text=True, timeout=300, check=False
    )


@pytest.mark.ros1
@pytest.mark.skipif(
    not Path("/usr/bin/catkin_make").exists() or not shutil.which("cmake"), reason="no catkin"
)
def test_same_pass_and_fail_as_debians_catkin_make(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, clean_env: None
) -> None:
    cases = {
        "loose": (LOOSE_XML, LOOSE_CMAKE, True),
        "needy": ("  <depend>rospy</depend>\n", MISSING_CMAKE, False),
        "nocmake": ("  <depend>rospy</depend>\n", None, False),
    }
    for name, (xml, cmake, passes) in cases.items():
        theirs, ours = tmp_path / f"{name}_debian", tmp_path / f"{name}_ours"
        for ws in (theirs, ours):
            pkg = _package(ws, name, xml, cmake or "")
            if cmake is None:  # a package.xml and a launch file only, as some book packages are
                (pkg / "CMakeLists.txt").unlink()
        debian = _debian_catkin_make(theirs)
        assert (debian.returncode == 0) is passes, debian.stdout + debian.stderr
        if passes:
            assert _make(ours, monkeypatch) == 0
            continue
        with pytest.raises(PackageError) as info:
            _make(ours, monkeypatch)
        first = next(line for line in (debian.stdout + debian.stderr).splitlines() if "CMake Error" in line)
        assert str(info.value).splitlines()[0] == first
        flat = " ".join((debian.stdout + debian.stderr).split())
        mine = str(info.value).split("\nninjemys:")[0].replace(str(ours), str(theirs))
        assert " ".join(mine.split()) in flat


def test_a_catkin_package_without_cmakelists_fails_like_catkin(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, clean_env: None
) -> None:
    """A book's package that holds only a launch file, a URDF and package.xml (no CMakeLists.txt):
    catkin's add_subdirectory refuses it, so catkin_make fails, naming the directory."""
    pkg = _package(tmp_path, "launch_only", "", "")
    (pkg / "CMakeLists.txt").unlink()
    with pytest.raises(PackageError) as info:
        _make(tmp_path, monkeypatch)
    text = str(info.value)
    assert text.startswith(
        "CMake Error at /usr/share/catkin/cmake/catkin_workspace.cmake:121 (add_subdirectory):"
    )
    assert f"    {pkg}\n\n  does not contain a CMakeLists.txt file." in text
    assert sum(line.startswith("ninjemys:") for line in text.splitlines()) == 1


def test_a_metapackage_without_cmakelists_only_warns(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, clean_env: None, capsys: pytest.CaptureFixture[str]
) -> None:
    pkg = _package(tmp_path, "meta_robot", "  <exec_depend>rospy</exec_depend>\n", "")
    (pkg / "CMakeLists.txt").unlink()
    xml = pkg / "package.xml"
    xml.write_text(xml.read_text().replace("</package>", "<export><metapackage/></export></package>"))
    assert _make(tmp_path, monkeypatch) == 0
    assert "WARNING: Add a CMakeLists.txt file to the metapackage 'meta_robot'" in capsys.readouterr().out


def test_a_ros2_package_in_the_workspace_fails_like_catkin(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, clean_env: None
) -> None:
    """ament packages beside catkin ones (course repositories that carry both): catkin refuses the
    non-homogeneous workspace; a build_type only for ROS 2 (condition) is not one."""
    pkg = _package(tmp_path, "dual", "", LOOSE_CMAKE)
    xml = pkg / "package.xml"
    dual = '<export><build_type condition="$ROS_VERSION == 2">ament_cmake</build_type></export></package>'
    xml.write_text(xml.read_text().replace("</package>", dual))
    assert _make(tmp_path, monkeypatch) == 0
    xml.write_text(xml.read_text().replace(' condition="$ROS_VERSION == 2"', ""))
    with pytest.raises(PackageError, match="non-homogeneous workspace") as info:
        _make(tmp_path, monkeypatch)
    assert "<build_type>ament_cmake</build_type>" in str(info.value)


def test_catkin_ignore_beside_a_package_xml_hides_the_package(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, clean_env: None
) -> None:
    pkg = _package(tmp_path, "cpp_only", "", MISSING_CMAKE)
    _package(tmp_path, "fine", "", LOOSE_CMAKE)
    (pkg / "CATKIN_IGNORE").touch()
    assert _make(tmp_path, monkeypatch) == 0
    assert (tmp_path / "devel" / "setup.bash").is_file()


#: MR3001C's links_act template lists two scripts its students have not written yet
GONE_SCRIPT_CMAKE = (
    "find_package(catkin REQUIRED COMPONENTS rospy)\n"
    "catkin_install_python(PROGRAMS\n  scripts/gone.py\n  DESTINATION bin\n)\n"
)


def test_an_install_python_program_that_is_missing_fails_with_catkins_words_and_its_line(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, clean_env: None
) -> None:
    pkg = _package(tmp_path, "gone", "  <depend>rospy</depend>\n", GONE_SCRIPT_CMAKE)
    with pytest.raises(PackageError) as info:
        _make(tmp_path, monkeypatch)
    assert str(info.value) == (
        f"{pkg}/CMakeLists.txt:4: catkin_install_python() called with non-existing file '{pkg}/scripts/gone.py'."
    )


@pytest.mark.ros1
@pytest.mark.skipif(
    not Path("/usr/bin/catkin_make").exists() or not shutil.which("cmake"), reason="no catkin"
)
def test_a_missing_install_python_program_fails_debians_catkin_make_the_same_way(tmp_path: Path) -> None:
    pkg = _package(tmp_path, "gone", "  <depend>rospy</depend>\n", GONE_SCRIPT_CMAKE)
    debian = _debian_catkin_make(tmp_path)
    assert debian.returncode != 0
    flat = " ".join((debian.stdout + debian.stderr).split())
    assert f"catkin_install_python() called with non-existing file '{pkg}/scripts/gone.py'." in flat
    assert "gone/CMakeLists.txt:4 (catkin_install_python)" in flat

"""xacro: the upstream language (macros with block parameters, includes, conditionals on args,
YAML, math) with ROS 1's ``$(find)``, from the command, from ``rosrun`` and from a launch file's
``command="$(find xacro)/xacro ..."``; errors name the file."""

from __future__ import annotations

import os
import subprocess
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest

from ninjemys.launch.xml import load_launch

BIN = Path(sys.executable).parent

WHEEL = """<?xml version="1.0"?>
<robot xmlns:xacro="http://www.ros.org/wiki/xacro">
  <xacro:macro name="wheel" params="side y *joint_extra">
    <link name="${side}_wheel"/>
    <joint name="${side}_wheel_joint" type="continuous">
      <parent link="base_link"/><child link="${side}_wheel"/>
      <origin xyz="0 ${y} 0.05" rpy="${-pi/2} 0 0"/>
      <xacro:insert_block name="joint_extra"/>
    </joint>
  </xacro:macro>
</robot>
"""
ROBOT = """<?xml version="1.0"?>
<robot name="mybot" xmlns:xacro="http://www.ros.org/wiki/xacro">
  <xacro:arg name="with_lidar" default="true"/>
  <xacro:property name="dims" value="${xacro.load_yaml('$(find mybot)/urdf/dims.yaml')}"/>
  <xacro:property name="sep" value="0.19"/>
  <xacro:include filename="$(find mybot)/urdf/wheel.xacro"/>
  <link name="base_link"><visual><geometry>
    <box size="${dims['base']['length']} ${dims['base']['width']} 0.1"/></geometry></visual></link>
  <xacro:wheel side="left" y="${sep/2}"><axis xyz="0 0 1"/></xacro:wheel>
  <xacro:wheel side="right" y="${-sep/2}"><axis xyz="0 0 1"/></xacro:wheel>
  <xacro:if value="$(arg with_lidar)">
    <link name="laser"/>
    <joint name="laser_joint" type="fixed"><parent link="base_link"/><child link="laser"/>
      <origin xyz="0 0 0.12" rpy="0 0 ${pi}"/></joint>
  </xacro:if>
  <xacro:unless value="$(arg with_lidar)"><link name="no_laser"/></xacro:unless>
</robot>
"""


@pytest.fixture
def workspace(tmp_path: Path) -> tuple[Path, dict[str, str]]:
    pkg = tmp_path / "src" / "mybot"
    (pkg / "urdf").mkdir(parents=True)
    (pkg / "launch").mkdir()
    (pkg / "package.xml").write_text(
        '<package format="2"><name>mybot</name><version>0.0.1</version><description>d</description>'
        '<maintainer email="dev@example.com">d</maintainer><license>BSD</license></package>'
    )
    (pkg / "urdf" / "wheel.xacro").write_text(WHEEL)
    (pkg / "urdf" / "dims.yaml").write_text("base: {length: 0.3, width: 0.2}\n")
    (pkg / "urdf" / "mybot.urdf.xacro").write_text(ROBOT)
    env = dict(os.environ, ROS_PACKAGE_PATH=str(tmp_path / "src"))
    return pkg, env


def _expand(
    args: list[str], env: dict[str, str], command: list[str] | None = None
) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [*(command or [str(BIN / "xacro")]), *args], env=env, capture_output=True, text=True, timeout=60
    )


def _check_robot(text: str, lidar: bool) -> None:
    root = ET.fromstring(text)
    assert root.get("name") == "mybot"
    assert [link.get("name") for link in root.findall("link")] == [
        "base_link",
        "left_wheel",
        "right_wheel",
        *(["laser"] if lidar else ["no_laser"]),
    ]
    assert root.find("link/visual/geometry/box").get("size") == "0.3 0.2 0.1"
    left = root.find("joint[@name='left_wheel_joint']")
    assert left.find("origin").get("xyz") == "0 0.095 0.05"
    assert left.find("origin").get("rpy") == "-1.5707963267948966 0 0"
    assert left.find("axis").get("xyz") == "0 0 1"
    assert root.find("joint[@name='right_wheel_joint']/origin").get("xyz") == "0 -0.095 0.05"
    if lidar:
        assert root.find("joint[@name='laser_joint']/origin").get("rpy") == "0 0 3.141592653589793"


def test_command_expands_macros_includes_conditionals_args_and_yaml(workspace) -> None:
    pkg, env = workspace
    result = _expand([str(pkg / "urdf" / "mybot.urdf.xacro")], env)
    assert result.returncode == 0, result.stderr
    _check_robot(result.stdout, lidar=True)
    result = _expand([str(pkg / "urdf" / "mybot.urdf.xacro"), "with_lidar:=false"], env)
    _check_robot(result.stdout, lidar=False)


def test_rosrun_xacro_and_the_legacy_name(workspace) -> None:
    pkg, env = workspace
    for name in ("xacro", "xacro.py"):
        result = _expand([str(pkg / "urdf" / "mybot.urdf.xacro")], env, [str(BIN / "rosrun"), "xacro", name])
        assert result.returncode == 0, result.stderr
        _check_robot(result.stdout, lidar=True)


def test_launch_command_attribute_runs_find_xacro(workspace) -> None:
    pkg, env = workspace
    env["PATH"] = "/usr/bin:/bin"  # roslaunch started by full path, the venv not activated
    (pkg / "launch" / "desc.launch").write_text(
        '<launch>\n  <arg name="lidar" default="false"/>\n'
        '  <param name="robot_description" command="$(find xacro)/xacro '
        "'$(find mybot)/urdf/mybot.urdf.xacro' with_lidar:=$(arg lidar)\"/>\n</launch>\n"
    )
    plan = load_launch([pkg / "launch" / "desc.launch"], env=env)
    _check_robot(plan.params["/robot_description"], lidar=False)


def test_errors_name_the_file_and_the_package(workspace, tmp_path: Path) -> None:
    pkg, env = workspace
    broken = tmp_path / "broken.xacro"
    broken.write_text('<robot xmlns:xacro="http://www.ros.org/wiki/xacro">\n<link name="a">\n</robot>\n')
    result = _expand([str(broken)], env)
    assert result.returncode != 0
    assert "broken.xacro" in result.stderr and "line 3" in result.stderr
    missing = tmp_path / "missing.xacro"
    missing.write_text(
        '<robot xmlns:xacro="http://www.ros.org/wiki/xacro"><xacro:include filename="$(find nosuch_pkg)/x.xacro"/></robot>'
    )
    result = _expand([str(missing)], env)
    assert result.returncode != 0
    assert "nosuch_pkg" in result.stderr and "missing.xacro" in result.stderr
    undefined = tmp_path / "undefined.xacro"
    undefined.write_text('<robot xmlns:xacro="http://www.ros.org/wiki/xacro"><link name="${nope}"/></robot>')
    result = _expand([str(undefined)], env)
    assert result.returncode != 0 and "nope" in result.stderr and "undefined.xacro" in result.stderr


def test_a_missing_package_and_a_missing_file_read_as_noetics_xacro(workspace, tmp_path: Path) -> None:
    """A description including a package this machine lacks (husky's accessories need Clearpath's
    mount packages) says ``resource not found: pkg`` and lists the ROS paths, as Noetic's xacro
    does; a model path given relative to the wrong directory (urdf_tutorial's ``model:=urdf/...``
    outside the package) is one error line and exit 2, never a traceback."""
    pkg, env = workspace
    parent = tmp_path / "parent.urdf.xacro"
    parent.write_text(
        '<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">\n'
        '  <xacro:include filename="$(find mount_description_not_here)/urdf/lockmount.urdf.xacro"/>\n</robot>\n'
    )
    result = _expand([str(parent)], env)
    assert result.returncode == 2
    assert "resource not found: mount_description_not_here\n" in result.stderr
    assert f"ROS path [0]={tmp_path / 'src'}" in result.stderr
    assert "when processing file: " + str(parent) in result.stderr
    assert "Traceback" not in result.stderr and "PackageNotFoundError" not in result.stderr
    result = subprocess.run(
        [str(BIN / "xacro"), "urdf/01-myfirst.urdf"], cwd=tmp_path, env=env, capture_output=True, text=True
    )
    assert result.returncode == 2
    assert "No such file or directory" in result.stderr and "01-myfirst.urdf" in result.stderr
    assert "Traceback" not in result.stderr and "AttributeError" not in result.stderr


SUBST = """<?xml version="1.0"?>
<robot name="subst" xmlns:xacro="http://www.ros.org/wiki/xacro">
  <xacro:arg name="scale" default="2"/>
  <xacro:property name="r" value="${radians(90)}"/>
  <link name="$(env MYBOT_NAME)"/>
  <link name="$(optenv MYBOT_UNSET fallback)"/>
  <link name="l$(eval 2 * 4 + 1)"/>
  <joint name="j" type="fixed"><parent link="fallback"/><child link="$(env MYBOT_NAME)"/>
    <origin xyz="${sin(r)} ${cos(pi)} ${$(arg scale) ** 2}" rpy="0 0 0"/></joint>
  <xacro:include filename="$(find mybot)/urdf/wheel.xacro"/>
  <xacro:wheel side="s" y="0"><axis xyz="1 0 0"/></xacro:wheel>
</robot>
"""


def test_process_file_in_a_script_resolves_find_env_optenv_eval_and_math(workspace) -> None:
    pkg, env = workspace
    (pkg / "urdf" / "subst.xacro").write_text(SUBST)
    env["MYBOT_NAME"] = "from_env"
    script = (
        "import sys, xacro\n"
        "doc = xacro.process_file(sys.argv[1], mappings={'scale': '3'})\n"
        "print(doc.toprettyxml(indent='  '))\n"
    )
    result = subprocess.run(
        [sys.executable, "-c", script, str(pkg / "urdf" / "subst.xacro")],
        env=env,
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert result.returncode == 0, result.stderr
    root = ET.fromstring(result.stdout)
    assert [link.get("name") for link in root.findall("link")] == ["from_env", "fallback", "l9", "s_wheel"]
    assert root.find("joint[@name='j']/origin").get("xyz") == "1.0 -1.0 9"
    # the command, with Noetic's --inorder flag (processing in order is the default), gives the same robot
    command = _expand([str(pkg / "urdf" / "subst.xacro"), "--inorder", "scale:=3"], env)
    assert command.returncode == 0, command.stderr
    assert ET.canonicalize(command.stdout, strip_text=True) == ET.canonicalize(
        result.stdout.split("?>", 1)[1], strip_text=True
    )


def test_same_xml_as_the_reference_xacro(workspace) -> None:
    """Ours (``xacro``, ``rosrun xacro xacro``) and upstream xacro's own ``main`` print the same bytes."""
    pkg, env = workspace
    reference = _expand(
        [str(pkg / "urdf" / "mybot.urdf.xacro"), "with_lidar:=false"],
        env,
        [sys.executable, "-c", "import sys, xacro; sys.argv[0] = 'xacro'; sys.exit(xacro.main())"],
    )
    ours = _expand([str(pkg / "urdf" / "mybot.urdf.xacro"), "with_lidar:=false"], env)
    assert reference.returncode == ours.returncode == 0, reference.stderr + ours.stderr
    assert ours.stdout == reference.stdout
    _check_robot(ours.stdout, lidar=False)

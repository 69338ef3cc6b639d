"""package.xml parsing: formats 1-3, dependency kinds, conditions, and file:line errors."""

from __future__ import annotations

from pathlib import Path

import pytest

from ninjemys.errors import PackageError
from ninjemys.packages.manifest import parse_manifest


def write(tmp_path: Path, text: str) -> Path:
    path = tmp_path / "package.xml"
    path.write_text(text)
    return path


def test_format1_run_depend_is_exec_and_build_export(tmp_path: Path) -> None:
    m = parse_manifest(
        write(
            tmp_path,
            "<package><name>old</name><version>1.2.3</version><description>d</description>"
            "<build_depend>genmsg</build_depend><run_depend>rospy</run_depend></package>",
        )
    )
    assert (m.name, m.version, m.format) == ("old", "1.2.3", 1)
    assert m.build_depends == ("genmsg",)
    assert m.exec_depends == ("rospy",)
    assert m.run_depends == ("rospy",)


def test_format2_depend_expands_to_build_export_and_exec(tmp_path: Path) -> None:
    m = parse_manifest(
        write(
            tmp_path,
            '<package format="2"><name>p</name><version>0.1.0</version><description>A  <b>bold</b>\n pkg</description>'
            '<maintainer email="a@b.c">A</maintainer><license>BSD</license>'
            "<buildtool_depend>catkin</buildtool_depend><depend>std_msgs</depend>"
            "<exec_depend>rospy</exec_depend><test_depend>rostest</test_depend></package>",
        )
    )
    assert m.build_depends == ("std_msgs",)
    assert m.build_export_depends == ("std_msgs",)
    assert m.exec_depends == ("std_msgs", "rospy")
    assert m.all_depends == ("catkin", "std_msgs", "rospy", "rostest")
    assert m.description == "A bold pkg"
    assert m.licenses == ("BSD",)
    assert m.path == tmp_path.resolve()


def test_format3_conditions_are_evaluated(tmp_path: Path) -> None:
    m = parse_manifest(
        write(
            tmp_path,
            '<package format="3"><name>c</name><version>1.0.0</version><description>d</description>'
            '<depend condition="$ROS_VERSION == 1">rospy</depend>'
            '<depend condition="$ROS_VERSION == 2">rclpy</depend></package>',
        )
    )
    assert m.exec_depends == ("rospy",)


def test_malformed_xml_names_file_and_line(tmp_path: Path) -> None:
    path = write(tmp_path, '<package format="2">\n<name>x</name>\n<version>1</versoin>\n</package>')
    with pytest.raises(PackageError) as err:
        parse_manifest(path)
    assert str(err.value).startswith(f"{path}:3: malformed package.xml")


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("<manifest/>", "root element must be <package>"),
        ('<package format="7"><name>x</name></package>', "unsupported package.xml format"),
        ('<package format="2"><version>1</version></package>', "has no <name>"),
        ('<package format="2"><name>bad-name</name></package>', "invalid package name"),
    ],
)
def test_invalid_manifests_are_rejected(tmp_path: Path, text: str, message: str) -> None:
    with pytest.raises(PackageError, match=message):
        parse_manifest(write(tmp_path, text))

"""check_urdf prints liburdfdom-tools' tree for a good URDF and, for a bad one, urdfdom's reason
with the URDF's own file and line; urdf_parser_py (the upstream urdfdom-py release) reads the same
documents."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

BIN = Path(sys.executable).parent
DEBIAN = Path("/usr/bin/check_urdf")

GOOD = """<robot name="arm">
  <link name="base"/><link name="l1"/><link name="l2"/><link name="l3"/><link name="l4"/>
  <joint name="j1" type="revolute"><parent link="base"/><child link="l1"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
  <joint name="j2" type="fixed"><parent link="base"/><child link="l2"/></joint>
  <joint name="j3" type="continuous"><parent link="l1"/><child link="l3"/></joint>
  <joint name="j4" type="prismatic"><parent link="l3"/><child link="l4"/>
    <limit lower="0" upper="1" effort="1" velocity="1"/><mimic joint="j1" multiplier="2" offset="0.1"/></joint>
</robot>
"""
BAD = {
    "no_limits": (
        '<robot name="x">\n<link name="a"/><link name="b"/>\n'
        '<joint name="j" type="revolute"><parent link="a"/><child link="b"/></joint>\n</robot>\n',
        "Joint [j] is of type REVOLUTE but it does not specify limits",
        3,
    ),
    "no_links": ('<robot name="x">\n</robot>\n', "No link elements found in urdf file", 1),
    "malformed": ('<robot name="x">\n<link name="a">\n</robot>\n', "malformed XML", 3),
    "unknown_link": (
        '<robot name="x">\n<link name="a"/>\n<link name="c"/>\n'
        '<joint name="j" type="fixed"><parent link="a"/><child link="b"/></joint>\n</robot>\n',
        "child link [b] of joint [j] not found",
        4,
    ),
}


def run(binary: Path, path: Path) -> subprocess.CompletedProcess[str]:
    return subprocess.run([str(binary), str(path)], capture_output=True, text=True, timeout=60)


def test_good_urdf_prints_the_link_tree(tmp_path: Path) -> None:
    path = tmp_path / "arm.urdf"
    path.write_text(GOOD)
    done = run(BIN / "check_urdf", path)
    assert done.returncode == 0, done.stderr
    assert done.stdout.splitlines() == [
        "robot name is: arm",
        "---------- Successfully Parsed XML ---------------",
        "root Link: base has 2 child(ren)",
        "    child(1):  l1",
        "        child(1):  l3",
        "            child(1):  l4",
        "    child(2):  l2",
    ]


@pytest.mark.parametrize("case", sorted(BAD))
def test_bad_urdf_names_reason_file_and_line(tmp_path: Path, case: str) -> None:
    text, reason, line = BAD[case]
    path = tmp_path / f"{case}.urdf"
    path.write_text(text)
    done = run(BIN / "check_urdf", path)
    assert done.returncode == 255
    lines = done.stderr.splitlines()
    assert lines[0].startswith("Error:   ") and reason in lines[0]
    assert lines[1] == f"         at line {line} in {path}"
    assert lines[-1] == "ERROR: Model Parsing the xml failed"
    assert "Traceback" not in done.stderr


def test_no_argument_is_urdfdoms_usage() -> None:
    done = subprocess.run([str(BIN / "check_urdf")], capture_output=True, text=True, timeout=60)
    assert (done.returncode, done.stderr.strip()) == (255, "Expect URDF xml file to parse")


@pytest.mark.ros1
@pytest.mark.skipif(not DEBIAN.exists(), reason="Debian's liburdfdom-tools is not installed")
def test_same_output_and_status_as_debians_check_urdf(tmp_path: Path) -> None:
    good = tmp_path / "arm.urdf"
    good.write_text(GOOD)
    ours, theirs = run(BIN / "check_urdf", good), run(DEBIAN, good)
    assert (ours.returncode, ours.stdout) == (theirs.returncode, theirs.stdout)
    for case, (text, _reason, _line) in BAD.items():
        path = tmp_path / f"{case}.urdf"
        path.write_text(text)
        ours, theirs = run(BIN / "check_urdf", path), run(DEBIAN, path)
        assert ours.returncode == theirs.returncode == 255, case
        # the first line is urdfdom's reason, except where expat and TinyXML word a syntax error differently
        if case != "malformed":
            assert ours.stderr.splitlines()[0] == theirs.stderr.splitlines()[0], case
        assert ours.stderr.splitlines()[-1] == theirs.stderr.splitlines()[-1]


def test_urdf_parser_py_reads_the_same_document(tmp_path: Path) -> None:
    from urdf_parser_py.urdf import URDF

    robot = URDF.from_xml_string(GOOD)
    assert robot.name == "arm"
    assert [j.name for j in robot.joints] == ["j1", "j2", "j3", "j4"]
    assert robot.joint_map["j4"].mimic.joint == "j1" and robot.joint_map["j4"].mimic.multiplier == 2
    assert robot.get_root() == "base"
    path = tmp_path / "arm.urdf"
    path.write_text(GOOD)
    assert [link.name for link in URDF.from_xml_file(str(path)).links] == ["base", "l1", "l2", "l3", "l4"]

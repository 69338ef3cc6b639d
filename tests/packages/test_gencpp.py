"""C++ headers for the message packages ninjemys ships: our generator writes what ROS 1's gencpp
writes (the same C++ tokens, checked against Debian's gencpp run on the same definitions), the
md5sums in the C++ traits equal ours and those of Debian's installed headers, and the prefix that
catkin_make's C++ build uses holds exactly the packages this machine has no C++ side of."""

from __future__ import annotations

import json
import re
import subprocess
from pathlib import Path

import pytest

from ninjemys.idl import loader
from ninjemys.packages import cpp_msgs
from ninjemys.packages.cpp_msgs import (
    has_cpp_side,
    packages_without_cpp_side,
    shipped_interface_packages,
    write_prefix,
)
from ninjemys.packages.gencpp import definition_literal, message_header

DEBIAN_GENCPP = Path("/usr/share/gencpp/msg.h.template")
#: packages only ninjemys provides, and one with many constants and fixed-size types
COMPARED = ("control_msgs", "gazebo_msgs", "fiducial_msgs", "rosserial_msgs", "visualization_msgs")

#: definitions that exercise every corner of the generator: constants of each kind (escapes in a
#: string constant), fixed-size arrays of strings, messages, times and numbers, an empty message
EDGE_MSG = """\
int8 NEG=-5
uint64 BIG=18446744073709551615
char LETTER=65
byte SMALL_BYTE=3
bool FLAG=True
float64 PI=3.14159
float32 TINY=1e-05
string GREETING=say "hi" \\ there
Header header
string[3] names
geometry_msgs/Point[2] corners
time[2] stamps
uint8[4] raw
float32[] values
bool ok
duration wait
std_msgs/Empty nothing
Nothing[] nothings
"""
EDGE_SRV = "---\nstring answer\nint32 CODE=7\n"

_TOKEN = re.compile(r'"(?:\\.|[^"\\])*"|//[^\n]*|#include[^\n]*|[A-Za-z_]\w*|\d[\w.]*|::|&&|\S')


def tokens(text: str) -> tuple[list[str], set[str]]:
    """C++ tokens without comments (adjacent string literals joined), and the included headers:
    layout and comments may differ from gencpp's, the code may not."""
    out: list[str] = []
    includes: set[str] = set()
    for token in _TOKEN.findall(text):
        if token.startswith("//"):
            continue
        if token.startswith("#include"):
            includes.add(token.split(None, 1)[1].strip())
        elif token.startswith('"') and out and out[-1].startswith('"'):
            out[-1] = out[-1][:-1] + token[1:]
        else:
            out.append(token)
    return out, includes


def _edge_package(root: Path) -> Path:
    pkg = root / "cppgen_edge"
    (pkg / "msg").mkdir(parents=True)
    (pkg / "srv").mkdir()
    (pkg / "package.xml").write_text(
        '<?xml version="1.0"?>\n<package format="2"><name>cppgen_edge</name><version>0.1.0</version>'
        "<description>d</description><maintainer email='a@b.c'>a</maintainer><license>BSD</license>"
        "</package>\n"
    )
    (pkg / "msg" / "Edge.msg").write_text(EDGE_MSG)
    (pkg / "msg" / "Nothing.msg").write_text("")
    (pkg / "srv" / "Ask.srv").write_text(EDGE_SRV)
    return pkg


@pytest.fixture(scope="module")
def prefix(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """Our headers for every shipped interface package (and the edge-case package)."""
    root = tmp_path_factory.mktemp("cpp_prefix")
    extra = _edge_package(root / "src")
    with pytest.MonkeyPatch.context() as mp:
        mp.setenv("ROS_PACKAGE_PATH", str(extra.parent))
        from ninjemys.idl import search

        search.clear_cache()
        try:
            wanted = [p for p in shipped_interface_packages() if p != "roscpp"] + ["cppgen_edge"]
            write_prefix(root / "prefix", wanted)
        finally:
            search.clear_cache()
    return root / "prefix"


@pytest.mark.ros1
@pytest.mark.skipif(not DEBIAN_GENCPP.is_file(), reason="Debian's gencpp (python3-gencpp) not installed")
def test_headers_match_debians_gencpp(prefix: Path, tmp_path: Path) -> None:
    """Debian's gencpp, given the definitions our prefix installs, writes the same C++ as ours."""
    share = prefix / "share"
    search_path = {d.name: str(d / "msg") for d in share.iterdir()}
    files = []
    for package in (*COMPARED, "cppgen_edge"):
        for kind in ("msg", "srv"):
            for path in sorted((share / package / kind).glob(f"*.{kind}")):
                files.append([package, str(path), str(tmp_path / package)])
    driver = (
        "import json, sys\nimport genmsg.template_tools as t\nargs = json.loads(sys.argv[1])\n"
        "for pkg, path, out in args['files']:\n"
        "    t.generate_from_file(path, pkg, out, '/usr/share/gencpp', "
        "[k + ':' + v for k, v in args['search'].items()], {'msg.h.template': '@NAME@.h'}, "
        "{'srv.h.template': '@NAME@.h'})\n"
    )
    run = subprocess.run(
        ["/usr/bin/python3", "-c", driver, json.dumps({"search": search_path, "files": files})],
        capture_output=True, text=True, timeout=600, check=False,
    )  # fmt: skip
    assert run.returncode == 0, run.stderr[-3000:]
    compared = 0
    for theirs in sorted(tmp_path.glob("*/*.h")):
        ours = prefix / "include" / theirs.parent.name / theirs.name
        assert ours.is_file(), f"we wrote no {ours}"
        assert tokens(ours.read_text()) == tokens(theirs.read_text()), f"{ours} differs from gencpp's"
        compared += 1
    assert compared > 150  # messages, actions' seven messages, services and their two parts


def _trait(header: str, trait: str) -> str:
    match = re.search(
        rf"struct {trait}< ::\w+::\w+_<ContainerAllocator> >\s*\{{\s*static const char\* value\(\)\s*"
        r'\{\s*return ((?:"(?:\\.|[^"\\])*"\s*)+);',
        header,
    )
    assert match is not None, trait
    return "".join(re.findall(r'"((?:\\.|[^"\\])*)"', match.group(1)))


def _service_md5(header: str) -> str:
    match = re.search(
        r'struct MD5Sum< ::\w+::\w+ > \{\s*static const char\* value\(\)\s*\{\s*return "(\w+)"', header
    )
    assert match is not None
    return match.group(1)


def _bool_trait(header: str, trait: str) -> str:
    match = re.search(rf"struct {trait}< ::\w+::\w+_<ContainerAllocator>\s*>\s*:\s*(\w+)", header)
    assert match is not None, trait
    return match.group(1)


@pytest.mark.ros1
@pytest.mark.skipif(not Path("/usr/include/std_msgs/Header.h").is_file(), reason="no Debian message headers")
def test_traits_equal_debians_installed_headers_and_ours(prefix: Path) -> None:
    """Where Debian installs a package's headers, ours have the same md5sum, type, fixed-size and
    header traits; and every md5sum in our headers is the one Python nodes send."""
    checked = 0
    for package in shipped_interface_packages():
        installed = Path("/usr/include") / package
        if not installed.is_dir() or package == "roscpp":
            continue
        for theirs in sorted(installed.glob("*.h")):
            ours = prefix / "include" / package / theirs.name
            their_text = theirs.read_text()
            if "struct MD5Sum< ::" not in their_text or not ours.is_file():
                continue
            our_text = ours.read_text()
            if "namespace message_traits" not in their_text:  # a service header
                assert _service_md5(our_text) == _service_md5(their_text), ours
                checked += 1
                continue
            for trait in ("MD5Sum", "DataType"):
                assert _trait(our_text, trait) == _trait(their_text, trait), (ours, trait)
            for trait in ("IsFixedSize", "HasHeader"):
                assert _bool_trait(our_text, trait) == _bool_trait(their_text, trait), (ours, trait)
            checked += 1
    assert checked >= 30, checked  # std_msgs (libstd-msgs-dev, installed by make test) at least
    for package in ("control_msgs", "gazebo_msgs", "std_msgs", "geometry_msgs"):
        for header in sorted((prefix / "include" / package).glob("*.h")):
            text = header.read_text()
            if "namespace message_traits" not in text:
                continue  # a service header: its md5 is checked through the service class below
            type_name = _trait(text, "DataType")
            assert _trait(text, "MD5Sum") == loader.get_message_md5(type_name), type_name
    service = (prefix / "include" / "gazebo_msgs" / "GetModelState.h").read_text()
    assert f'return "{loader.get_service_class("gazebo_msgs/GetModelState")._md5sum}";' in service


def test_definition_literal_is_one_literal_per_line_with_escapes() -> None:
    assert definition_literal('a "b"\nc\\d\n') == '"a \\"b\\"\\n"\n"c\\\\d\\n"\n'
    assert definition_literal("") == '"\\n"\n'


def test_empty_message_header_has_no_field_code() -> None:
    spec = loader.get_message_spec("std_msgs/Empty")
    header = message_header(spec, loader.get_message_spec, "d41d8cd98f00b204e9800998ecf8427e", "")
    assert "allInOne(Stream&, T)" in header and "operator==" not in header
    assert "static_value1 = 0xd41d8cd98f00b204ULL" in header


def test_packages_with_an_installed_cpp_side_are_left_to_it(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(cpp_msgs, "_SYSTEM_PREFIXES", ())
    monkeypatch.setattr(cpp_msgs, "_OPT_ROS", tmp_path / "no_opt_ros")
    system = tmp_path / "usr"
    (system / "share" / "nav_msgs" / "cmake").mkdir(parents=True)
    (system / "share" / "nav_msgs" / "cmake" / "nav_msgsConfig.cmake").write_text("")
    (system / "lib" / "x86_64-linux-gnu" / "cmake" / "tf").mkdir(parents=True)
    (system / "lib" / "x86_64-linux-gnu" / "cmake" / "tf" / "tfConfig.cmake").write_text("")
    assert has_cpp_side("nav_msgs", [system]) and has_cpp_side("tf", [system])
    assert not has_cpp_side("gazebo_msgs", [system])
    wanted = packages_without_cpp_side({"CMAKE_PREFIX_PATH": str(system)}, exclude={"fiducial_msgs"})
    assert "nav_msgs" not in wanted and "tf" not in wanted and "fiducial_msgs" not in wanted
    assert "gazebo_msgs" in wanted and "control_msgs" in wanted and "std_msgs" in wanted
    # never ours: roscpp, and packages whose real config brings CMake macros (add_action_files ...)
    assert not {"roscpp", "actionlib_msgs", "dynamic_reconfigure"} & set(wanted)


def test_prefix_is_rewritten_only_where_it_changed(tmp_path: Path) -> None:
    first = write_prefix(tmp_path / "p", ["fiducial_msgs", "smach_msgs"])
    assert (tmp_path / "p" / "include" / "fiducial_msgs" / "FiducialTransformArray.h").is_file()
    assert (tmp_path / "p" / ".catkin").is_file()  # catkin's CMake overlays it like a workspace
    config = (tmp_path / "p" / "share" / "fiducial_msgs" / "cmake" / "fiducial_msgsConfig.cmake").read_text()
    assert "find_package(${_ninjemys_fiducial_msgs_dep} REQUIRED NO_MODULE)" in config
    paths = (
        tmp_path / "p" / "share" / "fiducial_msgs" / "cmake" / "fiducial_msgs-msg-paths.cmake"
    ).read_text()
    assert "fiducial_msgs_MSG_DEPENDENCIES geometry_msgs;std_msgs" in paths
    assert first.written
    again = write_prefix(tmp_path / "p", ["fiducial_msgs", "smach_msgs"])
    assert again.written == []
    write_prefix(tmp_path / "p", ["fiducial_msgs"])
    assert not (tmp_path / "p" / "include" / "smach_msgs").exists()
    assert not (tmp_path / "p" / "share" / "smach_msgs").exists()


def test_actions_are_installed_as_their_seven_messages(tmp_path: Path) -> None:
    write_prefix(tmp_path / "p", ["control_msgs"])
    msg = tmp_path / "p" / "share" / "control_msgs" / "msg"
    for suffix in ("Action", "ActionGoal", "ActionResult", "ActionFeedback", "Goal", "Result", "Feedback"):
        assert (msg / f"FollowJointTrajectory{suffix}.msg").is_file()
        assert (tmp_path / "p" / "include" / "control_msgs" / f"FollowJointTrajectory{suffix}.h").is_file()
    extras = (
        tmp_path / "p" / "share" / "control_msgs" / "cmake" / "control_msgs-msg-extras.cmake"
    ).read_text()
    assert "msg/FollowJointTrajectoryActionGoal.msg" in extras and "srv/QueryTrajectoryState.srv" in extras

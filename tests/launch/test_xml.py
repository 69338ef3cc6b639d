"""The launch XML loader on its own: scoping corners, substitutions and file:line errors."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from ninjemys.errors import LaunchError
from ninjemys.launch.xml import load_launch

from .conftest import PKGS


def load(tmp_path: Path, body: str, argv: list[str] | None = None, name: str = "t.launch") -> object:
    path = tmp_path / name
    path.write_text(f"<launch>\n{body}\n</launch>\n")
    return load_launch([path], argv=argv or [], env={"ROS_PACKAGE_PATH": str(PKGS)})


def error(tmp_path: Path, body: str, argv: list[str] | None = None) -> str:
    with pytest.raises(LaunchError) as err:
        load(tmp_path, body, argv)
    return str(err.value)


def test_anon_is_stable_within_a_launch(tmp_path: Path) -> None:
    plan = load(
        tmp_path,
        '<node name="$(anon worker)" pkg="corpus_run" type="sleeper.py"/>\n'
        '<param name="who" value="$(anon worker)"/>\n'
        '<param name="other" value="$(anon other)"/>',
    )
    name = plan.nodes[0].name  # type: ignore[attr-defined]
    assert re.fullmatch(r"worker_\w+_\d+_\d+", name)
    assert plan.params["/who"] == name  # type: ignore[attr-defined]
    assert plan.params["/other"] != name  # type: ignore[attr-defined]


def test_command_line_arg_overrides_default_but_not_value(tmp_path: Path) -> None:
    plan = load(tmp_path, '<arg name="a" default="1"/><param name="p" value="$(arg a)"/>', ["a:=5"])
    assert plan.params["/p"] == 5  # type: ignore[attr-defined]
    assert "cannot override arg 'a'" in error(tmp_path, '<arg name="a" value="1"/>', ["a:=5"])


def test_args_declared_in_a_group_stay_in_the_group(tmp_path: Path) -> None:
    msg = error(
        tmp_path,
        '<group ns="g"><arg name="inner" default="x"/></group>\n<param name="p" value="$(arg inner)"/>',
    )
    assert msg.startswith(f"{tmp_path / 't.launch'}:3: arg 'inner' is not set")


def test_private_group_params_apply_to_following_nodes_only(tmp_path: Path) -> None:
    plan = load(
        tmp_path,
        '<group ns="g">\n<node name="before" pkg="corpus_run" type="sleeper.py"/>\n'
        '<param name="~rate" value="3"/>\n<node name="after" pkg="corpus_run" type="sleeper.py"/>\n</group>\n'
        '<node name="outside" pkg="corpus_run" type="sleeper.py"/>',
    )
    assert plan.params == {"/g/after/rate": 3}  # type: ignore[attr-defined]


def test_include_passes_only_declared_args(tmp_path: Path) -> None:
    (tmp_path / "inc.launch").write_text(
        '<launch><arg name="x"/><param name="got" value="$(arg x)"/></launch>'
    )
    plan = load(tmp_path, '<include file="$(dirname)/inc.launch" ns="i"><arg name="x" value="7"/></include>')
    assert plan.params == {"/i/got": 7}  # type: ignore[attr-defined]
    unused = error(
        tmp_path,
        '<include file="$(dirname)/inc.launch"><arg name="x" value="1"/><arg name="y" value="2"/></include>',
    )
    assert "unused args [y]" in unused
    missing = error(tmp_path, '<include file="$(dirname)/inc.launch"/>')
    assert "inc.launch:1: arg 'x' is not set" in missing


@pytest.mark.parametrize(
    ("body", "message"),
    [
        ('<param name="p" value="1" if="true" unless="false"/>', "cannot set both 'if' and 'unless'"),
        (
            '<node name="a" pkg="corpus_run" type="sleeper.py"/><node name="a" pkg="corpus_run" type="x"/>',
            "multiple nodes named [/a]",
        ),
        ('<param name="p" value="$(eval __import__(\'os\'))"/>', "may not contain double underscore"),
        ('<param name="p" value="$(eval open(\'/etc/passwd\'))"/>', "NameError"),
        ('<param name="p" value="$(bogus x)"/>', "Unknown substitution command [bogus x]"),
        (
            '<param name="p" value="$(env NJ_SURELY_UNSET_VAR)"/>',
            "environment variable 'NJ_SURELY_UNSET_VAR' is not set",
        ),
        ('<param name="p"/>', "must have one and only one of value/textfile/binfile"),
        (
            '<node name="a" pkg="corpus_run" type="sleeper.py" respawn="maybe"/>',
            "invalid bool value for respawn",
        ),
        ('<node pkg="corpus_run" type="sleeper.py"/>', "<node> tag is missing required attribute: 'name'"),
        ('<group clear_params="true"/>', "'ns' attribute must be set in order to use 'clear_params'"),
        ("<rosparam>a: [1, 2</rosparam>", "invalid YAML in YAML block"),
        ('<include file="nowhere.launch"/>', "does not exist"),
    ],
)
def test_errors_name_file_and_line(tmp_path: Path, body: str, message: str) -> None:
    msg = error(tmp_path, body)
    assert message in msg
    assert msg.startswith(f"{tmp_path / 't.launch'}:2:")


def test_binfile_and_textfile_params(tmp_path: Path) -> None:
    (tmp_path / "blob.bin").write_bytes(b"\x00\x01\xff")
    (tmp_path / "note.txt").write_text("hello\n")
    plan = load(
        tmp_path,
        '<param name="b" binfile="$(dirname)/blob.bin"/><param name="t" textfile="$(dirname)/note.txt"/>',
    )
    assert plan.params == {"/b": b"\x00\x01\xff", "/t": "hello\n"}  # type: ignore[attr-defined]


def test_ros_namespace_env_prefixes_everything(tmp_path: Path) -> None:
    path = tmp_path / "t.launch"
    path.write_text(
        '<launch><node name="a" pkg="corpus_run" type="sleeper.py"/><param name="p" value="1"/></launch>'
    )
    plan = load_launch([path], env={"ROS_PACKAGE_PATH": str(PKGS), "ROS_NAMESPACE": "/robot"})
    assert plan.node_names() == ["/robot/a"]
    assert plan.params == {"/robot/p": 1}


def test_an_illegal_node_name_warns_with_ros1s_lines_and_keeps_the_node(tmp_path: Path) -> None:
    """A student's launch file names its nodes after their scripts (``name="fake_scan.py"``):
    ROS 1's roslaunch warns (the name, the wiki page, the consequence) and starts the node."""
    plan = load(tmp_path, '<node pkg="rospy_tutorials" type="talker.py" name="fake_scan.py"/>')
    assert [n.name for n in plan.nodes] == ["fake_scan.py"]  # type: ignore[attr-defined]
    (warning,) = [w for w in plan.warnings if "illegal" in w]  # type: ignore[attr-defined]
    assert warning.endswith(
        "t.launch:2] illegal <node> name 'fake_scan.py'.\nhttp://ros.org/wiki/Names\n"
        "This will likely cause problems with other ROS tools."
    )


def test_a_missing_command_names_it_as_roslaunch_does(tmp_path: Path) -> None:
    # the mybot tutorial's `$(find xacro)/xacro.py` (Noetic's xacro has no xacro.py): roslaunch prints
    # the split command, "no such command [['/opt/ros/noetic/share/xacro/xacro.py', '.../mybot.xacro']]"
    text = error(
        tmp_path, '<param name="robot_description" command="/nonexistent/xacro.py \'/tmp/x/my bot.xacro\'"/>'
    )
    assert text.endswith(
        "Invalid <param> tag: Cannot load command parameter [robot_description]: no such command "
        "[['/nonexistent/xacro.py', '/tmp/x/my bot.xacro']]"
    ), text
    text = error(tmp_path, '<param name="robot_description" command="/bin/sh -c \'exit 3\'"/>')
    assert text.endswith("command [['/bin/sh', '-c', 'exit 3']] returned with code [3]"), text

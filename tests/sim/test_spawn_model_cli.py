"""spawn_model's command line and model sources without processes: every gazebo_ros option parses,
mesh URIs are rewritten by -package_to_model, and each source gives gazebo_ros' error line."""

from __future__ import annotations

import io
import sys
from pathlib import Path
from typing import Any

import pytest

from ninjemys.sim.spawn_model import DATABASE_TEMPLATE, parser, prepare_xml, read_model_xml


class FakeLog:
    def __init__(self) -> None:
        self.lines: list[str] = []

    def _add(self, msg: str, *args: Any) -> None:
        self.lines.append(msg % args)

    info = error = fatal = warn = _add


class FakeNode:
    def __init__(self, params: dict[str, Any]) -> None:
        self.params = params
        self.log = FakeLog()

    def has_param(self, key: str) -> bool:
        return key in self.params

    def get_param(self, key: str, default: Any = None) -> Any:
        return self.params.get(key, default)


def test_every_option_parses() -> None:
    args = parser().parse_args(
        "-urdf -param robot_description -model pb -x 1 -y 2 -z 0.1 -R 0.1 -P 0.2 -Y 3.1 "
        "-reference_frame world -gazebo_namespace /gz -robot_namespace /r1 -unpause -wait other "
        "-J wheel_left_joint 0.5 -J wheel_right_joint -0.5 -package_to_model -b".split()
    )
    assert args.urdf and not args.sdf and args.param == "robot_description" and args.model == "pb"
    assert (args.x, args.y, args.z, args.R, args.P, args.Y) == (1.0, 2.0, 0.1, 0.1, 0.2, 3.1)
    assert args.joints == [["wheel_left_joint", "0.5"], ["wheel_right_joint", "-0.5"]]
    assert args.unpause and args.wait == "other" and args.package_to_model and args.bond
    assert (args.gazebo_namespace, args.robot_namespace, args.reference_frame) == ("/gz", "/r1", "world")


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        ("-param p -model m", "one of the arguments -urdf -sdf is required"),
        ("-urdf -model m", "one of the arguments -file -param -database -stdin is required"),
        ("-urdf -param p", "the following arguments are required: -model"),
        ("-urdf -sdf -param p -model m", "argument -sdf: not allowed with argument -urdf"),
    ],
)
def test_usage_errors_are_argparse_lines(argv: str, message: str, capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit) as exc:
        parser().parse_args(argv.split())
    assert exc.value.code == 2
    err = capsys.readouterr().err
    assert err.startswith("usage: spawn_model") and message in err


def test_sources_and_their_errors(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    p = parser()
    node = FakeNode({"robot_description": "<robot name='r'/>", "empty": ""})
    assert (
        read_model_xml(node, p.parse_args("-urdf -param robot_description -model m".split()))
        == "<robot name='r'/>"
    )
    assert read_model_xml(node, p.parse_args("-urdf -param empty -model m".split())) is None
    assert node.log.lines[-1] == "Error: param does not exist or is empty"
    assert read_model_xml(node, p.parse_args("-urdf -param missing -model m".split())) is None
    assert read_model_xml(node, p.parse_args(f"-sdf -file {tmp_path} -model m".split())) is None
    assert node.log.lines[-1] == f"Error: specified file {tmp_path} is not a file"
    empty = tmp_path / "empty.sdf"
    empty.write_text("")
    assert read_model_xml(node, p.parse_args(f"-sdf -file {empty} -model m".split())) is None
    assert node.log.lines[-1] == f"Error: file {empty} is empty"
    assert read_model_xml(
        node, p.parse_args("-sdf -database crate -model m".split())
    ) == DATABASE_TEMPLATE.format("crate")
    monkeypatch.setattr(sys, "stdin", io.StringIO(""))
    assert read_model_xml(node, p.parse_args("-sdf -stdin -model m".split())) is None
    assert node.log.lines[-1] == "Error: stdin buffer was empty"


def test_package_to_model_rewrites_mesh_uris() -> None:
    text = (
        "<robot name='r'><link name='a'><visual><geometry><mesh filename='package://pb/meshes/base.stl'/>"
        "</geometry></visual><collision><geometry><mesh filename='file:///tmp/x.stl'/></geometry></collision>"
        "</link></robot>"
    )
    out = prepare_xml(text, True)
    assert "model://pb/meshes/base.stl" in out and "file:///tmp/x.stl" in out
    assert "package://pb/meshes/base.stl" in prepare_xml(text, False)

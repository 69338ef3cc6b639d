"""The web app's /api/resource route: package files by package:// and file:// URI, nothing else."""

from __future__ import annotations

from pathlib import Path

import pytest

from ninjemys.serve.http import HttpError, Request
from ninjemys.web.resources import Resources


def make_package(root: Path, name: str = "mesh_bot") -> Path:
    pkg = root / "src" / name
    (pkg / "meshes").mkdir(parents=True)
    (pkg / "package.xml").write_text(
        f'<package format="2"><name>{name}</name><version>0.0.1</version>'
        "<description>d</description><maintainer email='a@b.c'>a</maintainer>"
        "<license>BSD</license></package>"
    )
    (pkg / "meshes" / "base.stl").write_bytes(b"solid s\nendsolid s\n")
    return pkg


def request(uri: str | None) -> Request:
    return Request("GET", "/api/resource", {"uri": [uri]} if uri is not None else {}, {})


def test_package_and_file_uris_inside_a_package_are_served(tmp_path):
    pkg = make_package(tmp_path)
    res = Resources({"ROS_PACKAGE_PATH": str(tmp_path / "src")})
    resp = res.handle(request("package://mesh_bot/meshes/base.stl"))
    assert resp.body == b"solid s\nendsolid s\n" and resp.content_type == "model/stl"
    assert res.handle(request(f"file://{pkg}/meshes/base.stl")).body == resp.body
    # shipped packages are found too (they come after ROS_PACKAGE_PATH, as with rospack)
    assert res.resolve("package://puzzlebot_sim/package.xml").name == "package.xml"


@pytest.mark.parametrize(
    ("uri", "status", "pattern"),
    [
        ("package://mesh_bot/../../secret.txt", 403, "points outside package 'mesh_bot'"),
        ("file:///etc/passwd", 403, "not inside a ROS package"),
        (
            "package://no_such_pkg/x.stl",
            404,
            "package 'no_such_pkg' of package://no_such_pkg/x.stl not found",
        ),
        ("package://mesh_bot/meshes/nope.stl", 404, "no such file"),
        ("http://example.com/x.stl", 400, "expected a package:// or file:// URI"),
        (None, 400, "needs \\?uri="),
    ],
)
def test_everything_else_is_refused_with_a_reason(tmp_path, uri, status, pattern):
    make_package(tmp_path)
    (tmp_path / "secret.txt").write_text("no")
    res = Resources({"ROS_PACKAGE_PATH": str(tmp_path / "src")})
    with pytest.raises(HttpError, match=pattern) as info:
        res.handle(request(uri))
    assert info.value.status == status


def test_a_symlink_out_of_the_package_is_refused(tmp_path):
    pkg = make_package(tmp_path)
    (tmp_path / "outside.stl").write_text("solid x\n")
    (pkg / "meshes" / "link.stl").symlink_to(tmp_path / "outside.stl")
    res = Resources({"ROS_PACKAGE_PATH": str(tmp_path / "src")})
    with pytest.raises(HttpError, match="points outside"):
        res.resolve("package://mesh_bot/meshes/link.stl")

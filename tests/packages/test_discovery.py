"""Package discovery: ROS_PACKAGE_PATH overlays the shipped underlay; rospack queries."""

from __future__ import annotations

from pathlib import Path

import pytest

from ninjemys.errors import PackageError
from ninjemys.packages.discovery import PackageIndex, underlay_dirs


def make_pkg(root: Path, name: str, deps: tuple[str, ...] = (), version: str = "0.1.0") -> Path:
    root.mkdir(parents=True, exist_ok=True)
    deps_xml = "".join(f"<depend>{d}</depend>" for d in deps)
    (root / "package.xml").write_text(
        f'<package format="2"><name>{name}</name><version>{version}</version>'
        f"<description>d</description>{deps_xml}</package>"
    )
    return root


def test_shipped_packages_are_the_underlay() -> None:
    index = PackageIndex.from_environment({})
    for name in (
        "std_msgs",
        "geometry_msgs",
        "turtlesim",
        "rospy_tutorials",
        "rqt_graph",
        "rosbag",
        "rosout",
    ):
        assert name in index.packages, name
    assert all(d.is_dir() for d in underlay_dirs())


def test_workspace_overlays_underlay_and_first_path_entry_wins(tmp_path: Path) -> None:
    a = make_pkg(tmp_path / "ws1" / "src" / "std_msgs", "std_msgs", version="9.9.9")
    make_pkg(tmp_path / "ws2" / "src" / "mine", "mine", version="1.0.0")
    make_pkg(tmp_path / "ws2" / "src" / "std_msgs_copy", "std_msgs", version="8.8.8")
    env = {"ROS_PACKAGE_PATH": f"{tmp_path / 'ws1' / 'src'}:{tmp_path / 'ws2' / 'src'}"}
    index = PackageIndex.from_environment(env)
    assert index.find("std_msgs").path == a.resolve()
    assert index.find("std_msgs").version == "9.9.9"
    assert index.find("mine").version == "1.0.0"


def test_crawl_skips_ignored_and_nested_packages(tmp_path: Path) -> None:
    make_pkg(tmp_path / "outer", "outer")
    make_pkg(tmp_path / "outer" / "inner", "inner")
    make_pkg(tmp_path / "ignored" / "hidden_pkg", "hidden_pkg")
    (tmp_path / "ignored" / "CATKIN_IGNORE").touch()
    make_pkg(tmp_path / ".dot" / "dotpkg", "dotpkg")
    index = PackageIndex.scan([tmp_path])
    assert set(index.packages) == {"outer"}


def test_duplicates_under_one_root_are_recorded(tmp_path: Path) -> None:
    make_pkg(tmp_path / "a", "twin")
    make_pkg(tmp_path / "b", "twin")
    index = PackageIndex.scan([tmp_path])
    assert len(index.duplicates["twin"]) == 2


def test_depends_and_depends_on(tmp_path: Path) -> None:
    make_pkg(tmp_path / "base", "base")
    make_pkg(tmp_path / "mid", "mid", deps=("base", "rospy_not_here"))
    make_pkg(tmp_path / "top", "top", deps=("mid",))
    index = PackageIndex.scan([tmp_path])
    assert index.depends("top") == ["base", "mid"]
    assert index.depends("top", recursive=False) == ["mid"]
    assert index.depends_on("base") == ["mid", "top"]
    assert index.depends_on("base", recursive=False) == ["mid"]


def test_unknown_package_error() -> None:
    with pytest.raises(PackageError, match="package 'nope_nope' not found"):
        PackageIndex.from_environment({}).find("nope_nope")

"""A catkin workspace: its spaces, its packages in dependency order, and what it depends on.

Validation happens here, before anything is written: malformed package.xml (file:line), two
packages with one name, a dependency that is neither in the workspace, nor visible on
ROS_PACKAGE_PATH / in ninjemys, nor a tool ninjemys provides itself (catkin, rospy, ...), and
dependency cycles. Each is a PackageError that names the package and the file.
"""

from __future__ import annotations

import os
import re
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path

from ninjemys.errors import PackageError
from ninjemys.packages.discovery import PackageIndex, crawl, package_path_dirs, underlay_dirs
from ninjemys.packages.manifest import MANIFEST, PackageManifest, parse_manifest
from ninjemys.packages.setup_scripts import underlay_workspaces

#: packages that exist in ROS 1 as build tooling or C++/Python client libraries; ninjemys provides
#: their role itself, so depending on them is always satisfied.
PROVIDED = frozenset(
    {
        "catkin",
        "genmsg",
        "genpy",
        "gencpp",
        "geneus",
        "genlisp",
        "gennodejs",
        "message_generation",
        "message_runtime",
        "rospy",
        "roscpp",
        "rosgraph",
        "rosgraph_msgs",
        "roslib",
        "rospack",
        "roslaunch",
        "rostest",
        "rosunit",
        "rosbag",
        "rosout",
        "rosparam",
        "rostopic",
        "rosnode",
        "rosservice",
        "rosmsg",
        "actionlib",
        "tf",
        "tf2_ros",
        "cpp_common",
        "roscpp_serialization",
        "rostime",
        "xmlrpcpp",
        "rosconsole",
        "message_filters",
        "dynamic_reconfigure",
    }
)


def is_system_dependency(name: str) -> bool:
    """rosdep keys (python3-numpy, libopencv-dev, boost, eigen) are system packages, not ROS ones."""
    return bool(re.search(r"[-.]", name)) or name.startswith(("python", "lib")) or name in {"boost", "eigen"}


@dataclass
class Workspace:
    """``root`` holds ``src`` (sources), ``build`` and ``devel`` (outputs)."""

    root: Path
    source: Path
    build: Path
    devel: Path
    packages: list[PackageManifest] = field(default_factory=list)

    @classmethod
    def at(
        cls, root: str | Path, source: str | Path | None = None, build: str | Path | None = None
    ) -> Workspace:
        root = Path(root).resolve()
        src = Path(source).resolve() if source else root / "src"
        bld = Path(build).resolve() if build else root / "build"
        return cls(root=root, source=src, build=bld, devel=root / "devel")

    def load(self) -> None:
        """Find and parse every package under ``source``; duplicates are an error."""
        if not self.source.is_dir():
            raise PackageError(f'The specified source space "{self.source}" does not exist')
        seen: dict[str, Path] = {}
        packages = []
        for pkg_dir in crawl(self.source):
            manifest = parse_manifest(pkg_dir / MANIFEST)
            if manifest.name in seen:
                raise PackageError(
                    f"two packages are named '{manifest.name}': {seen[manifest.name] / MANIFEST} "
                    f"and {pkg_dir / MANIFEST}"
                )
            seen[manifest.name] = pkg_dir
            packages.append(manifest)
        self.packages = packages

    def check_dependencies(self, env: Mapping[str, str] | None = None) -> None:
        """Every build/run dependency must be resolvable; the first missing one is reported."""
        env = os.environ if env is None else env
        local = {p.name for p in self.packages}
        underlay_sources = [u.source for u in underlay_workspaces(self.devel, env) if u.source.is_dir()]
        index = PackageIndex.scan(package_path_dirs(env) + underlay_sources + underlay_dirs())
        for pkg in self.packages:
            for dep in pkg.all_depends:
                if dep in local or dep in PROVIDED or dep in index.packages or is_system_dependency(dep):
                    continue
                raise PackageError(
                    f"{pkg.path / MANIFEST}: package '{pkg.name}' depends on '{dep}', which is neither in "
                    f"the workspace ({self.source}) nor on ROS_PACKAGE_PATH nor shipped with ninjemys"
                )

    def ordered(self) -> list[PackageManifest]:
        """Packages in dependency order (dependencies first; ties by name); cycles are an error."""
        by_name = {p.name: p for p in self.packages}
        order: list[PackageManifest] = []
        state: dict[str, int] = {}

        def visit(name: str, chain: list[str]) -> None:
            if state.get(name) == 2:
                return
            if state.get(name) == 1:
                cycle = " -> ".join([*chain[chain.index(name) :], name])
                raise PackageError(f"circular dependency between workspace packages: {cycle}")
            state[name] = 1
            for dep in by_name[name].all_depends:
                if dep in by_name:
                    visit(dep, [*chain, name])
            state[name] = 2
            order.append(by_name[name])

        for name in sorted(by_name):
            visit(name, [])
        return order

"""A catkin workspace: its spaces, its packages in dependency order, and what it depends on.

Validation happens here, before anything is written: malformed package.xml (file:line), two
packages with one name, dependency cycles, and a package that CMakeLists.txt requires with
``find_package(... REQUIRED ...)`` and that is found nowhere: not in the workspace, not on
ROS_PACKAGE_PATH or in an underlay, not shipped with ninjemys, not a role ninjemys plays itself
(catkin, rospy, ...), and not a CMake package installed on the system. That is exactly where real
catkin fails; a dependency named only in package.xml (a ``<test_depend>`` on a C++ tutorial, an
``<exec_depend>`` installed later) never fails a catkin build, so it does not fail ours. Each error is
a PackageError in CMake's words plus one line of ours saying where the name could come from.
"""

from __future__ import annotations

import os
import re
import textwrap
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path

from ninjemys.errors import PackageError
from ninjemys.packages.cmake_hints import Requirement, read_cmake_hints
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

#: C++ libraries outside ROS whose CMake names look like ROS package names (lower case):
#: find_package(gazebo REQUIRED) in a robot's world package is for Gazebo plugins in C++, which a
#: Python build does not need, so a missing one is a note like Boost's, not a failure
SYSTEM_LIBRARIES = frozenset(
    {
        "gazebo",
        "orocos_kdl",
        "urdfdom",
        "urdfdom_headers",
        "console_bridge",
        "octomap",
        "fcl",
        "ompl",
        "sdformat",
    }
)


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

    def check_layout(self) -> list[str]:
        """What catkin_workspace.cmake checks before it configures anything: every package is built
        by catkin (a ``<build_type>`` of cmake or ament makes the workspace "non-homogeneous"), and
        every catkin package has a CMakeLists.txt (add_subdirectory needs one; only a metapackage
        gets a generated one, with a warning). Raises PackageError with CMake's text and one hint;
        returns the metapackage warnings."""
        notes: list[str] = []
        for pkg in self.packages:
            build_type = pkg.exports.get("build_type") or "catkin"
            if build_type != "catkin" and "metapackage" not in pkg.exports:
                raise PackageError(
                    f"CMake Error at /usr/share/catkin/cmake/catkin_workspace.cmake:100 (message):\n"
                    "  This workspace contains non-catkin packages in it, and catkin cannot build a\n"
                    "  non-homogeneous workspace without isolation.  Try the\n"
                    "  'catkin_make_isolated' command instead.\n\n"
                    f"ninjemys: {pkg.path / MANIFEST} declares <build_type>{build_type}</build_type>; "
                    "build it apart from this workspace, or add a CATKIN_IGNORE file beside its package.xml"
                )
        for pkg in self.packages:
            if (pkg.path / "CMakeLists.txt").is_file():
                continue
            rel = pkg.path.relative_to(self.source) if pkg.path.is_relative_to(self.source) else pkg.path
            if "metapackage" in pkg.exports:
                notes.append(f"WARNING: Add a CMakeLists.txt file to the metapackage '{pkg.name}'")
                continue
            raise PackageError(
                "CMake Error at /usr/share/catkin/cmake/catkin_workspace.cmake:121 (add_subdirectory):\n"
                f"  The source directory\n\n    {pkg.path}\n\n  does not contain a CMakeLists.txt file.\n"
                "Call Stack (most recent call first):\n"
                f"  CMakeLists.txt:{_workspace_call_line(self.source)} (catkin_workspace)\n\n"
                f"ninjemys: {rel}/package.xml makes '{pkg.name}' a catkin package: give it a CMakeLists.txt "
                "(catkin_create_pkg writes one), or a CATKIN_IGNORE file if it is not meant to be built"
            )
        return notes

    def check_dependencies(self, env: Mapping[str, str] | None = None) -> list[str]:
        """Every package a ``find_package(... REQUIRED ...)`` names must be found; the first missing
        one raises CMake's error. Returns notes for system libraries (Boost, OpenCV ...) that a
        C++ part would need and that are not installed: a Python build does not need them."""
        env = os.environ if env is None else env
        local = {p.name for p in self.packages}
        underlay_sources = [u.source for u in underlay_workspaces(self.devel, env) if u.source.is_dir()]
        index = PackageIndex.scan(package_path_dirs(env) + underlay_sources + underlay_dirs())
        notes: list[str] = []
        for pkg in self.packages:
            for req in read_cmake_hints(pkg.path).required:
                name = req.name
                if (
                    name in local
                    or name in PROVIDED
                    or name in index.packages
                    or cmake_config_found(name, env)
                ):
                    continue
                if req.catkin or (_ROS_NAME.fullmatch(name) and name not in SYSTEM_LIBRARIES):
                    raise PackageError(_missing_package_text(self.source, pkg, req))
                notes.append(
                    f"-- ninjemys: {pkg.path.name}/CMakeLists.txt:{req.line}: find_package({name} REQUIRED) "
                    "names a system library that is not installed; only C++ targets would need it"
                )
        return notes

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


_ROS_NAME = re.compile(r"[a-z][a-z0-9_]*")


def _workspace_call_line(source: Path) -> int:
    """The line of ``catkin_workspace()`` in the toplevel CMakeLists.txt CMake would run: the
    workspace's own, else catkin's toplevel.cmake (what real catkin_make links there)."""
    for candidate in (source / "CMakeLists.txt", Path("/usr/share/catkin/cmake/toplevel.cmake")):
        try:
            lines = candidate.read_text(encoding="utf-8", errors="replace").splitlines()
        except OSError:
            continue
        for number, line in enumerate(lines, 1):
            if line.strip().startswith("catkin_workspace("):
                return number
    return 7  # the line in the toplevel file ninjemys writes


def _system_prefixes(env: Mapping[str, str]) -> list[Path]:
    prefixes = [Path(p) for p in env.get("CMAKE_PREFIX_PATH", "").split(os.pathsep) if p]
    prefixes += [Path("/usr/local"), Path("/usr")]
    opt_ros = Path("/opt/ros")
    if opt_ros.is_dir():
        prefixes += sorted(opt_ros.iterdir())
    return prefixes


def cmake_config_found(name: str, env: Mapping[str, str] | None = None) -> bool:
    """Whether CMake's find_package would find ``name`` on this system: a ``<name>Config.cmake`` /
    ``<name>-config.cmake`` in the usual places under each prefix, or a ``Find<name>.cmake`` module
    shipped with CMake (Boost, PythonInterp ...)."""
    env = os.environ if env is None else env
    files = {f"{name}Config.cmake".lower(), f"{name}-config.cmake".lower()}
    lowered = name.lower()
    for prefix in _system_prefixes(env):
        roots = [prefix / "share", prefix / "lib" / "cmake", prefix / "lib"]
        roots += [d / "cmake" for d in (prefix / "lib").glob("*-linux-gnu*")]
        for root in roots:
            for directory in (root / name / "cmake", root / name):
                if _holds_config(directory, files):
                    return True
            if root.name == "cmake" and root.is_dir():
                for directory in root.iterdir():
                    if directory.name.lower().startswith(lowered) and _holds_config(directory, files):
                        return True
    return any(Path("/usr/share").glob(f"cmake*/Modules/Find{name}.cmake"))


def _holds_config(directory: Path, files: set[str]) -> bool:
    try:
        return any(entry.name.lower() in files for entry in directory.iterdir())
    except OSError:
        return False


def _missing_package_text(source: Path, pkg: PackageManifest, req: Requirement) -> str:
    """CMake's error for a package find_package cannot find, as catkin_make prints it, and a hint."""
    name = req.name
    where = f"{pkg.path.relative_to(source) if pkg.path.is_relative_to(source) else pkg.path}/CMakeLists.txt"
    body = (
        f'Could not find a package configuration file provided by "{name}" with any of the following '
        f"names:\n\n    {name}Config.cmake\n    {name}-config.cmake\n\n"
        f'Add the installation prefix of "{name}" to CMAKE_PREFIX_PATH or set "{name}_DIR" to a directory '
        f'containing one of the above files.  If "{name}" provides a separate development package or SDK, '
        "be sure it has been installed."
    )
    lines = []
    for paragraph in body.split("\n\n"):
        if paragraph.startswith("    "):
            lines.append(paragraph)
        else:
            lines.append("\n".join(textwrap.wrap(paragraph, 74, initial_indent="  ", subsequent_indent="  ")))
    if req.catkin:
        head = "CMake Error at /usr/share/catkin/cmake/catkinConfig.cmake:82 (find_package):"
        tail = f"\nCall Stack (most recent call first):\n  {where}:{req.line} (find_package)"
    else:
        head = f"CMake Error at {where}:{req.line} (find_package):"
        tail = ""
    hint = (
        f"ninjemys: '{name}' (required by {pkg.name}) is not in this workspace, on ROS_PACKAGE_PATH, "
        "in a sourced underlay or shipped with ninjemys: put its source into src/ or source the "
        "setup.bash of a workspace that has it"
    )
    return head + "\n" + "\n\n".join(lines) + tail + "\n\n" + hint

"""``catkin_create_pkg NAME [DEPS...]``: a new package, usable at once (package.xml, CMakeLists.txt, src/)."""

from __future__ import annotations

import argparse
import getpass
import re
from pathlib import Path

from ninjemys.errors import PackageError
from ninjemys.packages.templates import cmakelists, package_xml
from ninjemys.tools.cli import entry


def _parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="catkin_create_pkg", description="Creates a new catkin package")
    p.add_argument("name", help="The name for the package")
    p.add_argument("dependencies", nargs="*", help="Catkin package Dependencies")
    p.add_argument("-s", "--sys-deps", nargs="*", default=[], help="System Dependencies")
    p.add_argument("-b", "--boost-comps", nargs="*", default=[], help="Boost Components (accepted, unused)")
    p.add_argument("-V", "--pkg_version", default="0.0.0", help="Initial Package version")
    p.add_argument("-D", "--description", default="The {name} package", help="Description")
    p.add_argument("-l", "--license", default="TODO", help="Name for License, (e.g. BSD, MIT, GPLv3...)")
    p.add_argument(
        "-a", "--author", action="append", default=[], help="A single author, may be used multiple times"
    )
    p.add_argument("-m", "--maintainer", action="append", default=[], help="A single maintainer")
    p.add_argument("--rosdistro", default="noetic", help="The ROS distro (default: noetic)")
    p.add_argument("--meta", action="store_true", help="Creates meta-package files (not supported)")
    return p


def main(argv: list[str] | None = None) -> int:
    args = _parser().parse_args(argv)
    name = args.name
    if not re.match(r"^[a-z][a-z0-9_]*$", name):
        raise PackageError(
            f"invalid package name '{name}': use lowercase letters, digits and underscores, starting with a letter"
        )
    if args.meta:
        raise PackageError("--meta packages are not supported by ninjemys' catkin_create_pkg")
    deps = list(dict.fromkeys(args.dependencies + args.sys_deps))
    target = Path.cwd() / name
    if (target / "package.xml").exists():
        raise PackageError(f"File exists: {target / 'package.xml'}")
    user = getpass.getuser() if args.maintainer == [] else args.maintainer[0]
    xml = package_xml(
        name,
        deps,
        version=args.pkg_version,
        description=args.description.format(name=name),
        maintainer=user,
        email=f"{user}@todo.todo",
        license_=args.license,
    )
    target.mkdir(parents=True, exist_ok=True)
    (target / "package.xml").write_text(xml, encoding="utf-8")
    print(f"Created file {name}/package.xml")
    (target / "CMakeLists.txt").write_text(cmakelists(name, deps), encoding="utf-8")
    print(f"Created file {name}/CMakeLists.txt")
    if "roscpp" in deps:
        (target / "include" / name).mkdir(parents=True, exist_ok=True)
        print(f"Created folder {name}/include/{name}")
    (target / "src").mkdir(exist_ok=True)
    print(f"Created folder {name}/src")
    print(f"Successfully created files in {target}. Please adjust the values in package.xml.")
    return 0


console_main = entry(main)

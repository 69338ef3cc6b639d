"""``rosversion PKG`` / ``rosversion -d``: the version in a package's package.xml, or the distro name."""

from __future__ import annotations

import argparse

from ninjemys.packages.discovery import PackageIndex
from ninjemys.tools.cli import entry


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(prog="rosversion", description="Print the version of a ROS package")
    p.add_argument("-d", "--distro", action="store_true", help="print the ROS distribution name")
    p.add_argument("-s", "--skip-newline", action="store_true", help="no newline after the version")
    p.add_argument("package", nargs="?")
    args = p.parse_args(argv)
    end = "" if args.skip_newline else "\n"
    if args.distro or not args.package:
        if not args.distro:
            p.error("a package name or -d is required")
        print("noetic", end=end)
        return 0
    print(PackageIndex.from_environment().find(args.package).version, end=end)
    return 0


console_main = entry(main)

"""``rospack find|list|list-names|depends|depends1|depends-on|depends-on1|export``: package queries."""

from __future__ import annotations

import argparse
import sys

from ninjemys.errors import PackageError
from ninjemys.packages.discovery import PackageIndex
from ninjemys.tools.cli import entry

_COMMANDS = ("find", "list", "list-names", "depends", "depends1", "depends-on", "depends-on1", "profile")


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(prog="rospack", description="ROS package queries (ninjemys)")
    p.add_argument("command", choices=_COMMANDS)
    p.add_argument("package", nargs="?")
    args = p.parse_args(argv)
    index = PackageIndex.from_environment()
    try:
        if args.command in ("list", "profile"):
            for name in index.names():
                print(f"{name} {index.packages[name].path}")
        elif args.command == "list-names":
            print("\n".join(index.names()))
        else:
            if not args.package:
                print(f"[rospack] Error: no package given to {args.command}", file=sys.stderr)
                return 1
            if args.command == "find":
                print(index.find(args.package).path)
            elif args.command in ("depends", "depends1"):
                deps = index.depends(args.package, recursive=args.command == "depends")
                if deps:
                    print("\n".join(deps))
            else:
                users = index.depends_on(args.package, recursive=args.command == "depends-on")
                if users:
                    print("\n".join(users))
    except PackageError as exc:
        print(f"[rospack] Error: {exc}", file=sys.stderr)
        return 1
    return 0


console_main = entry(main)

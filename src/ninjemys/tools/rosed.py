"""``rosed PKG FILE``: open a file of a package in $EDITOR (default vim), as ROS 1's rosed."""

from __future__ import annotations

import argparse
import os
import shlex
from pathlib import Path

from ninjemys.errors import PackageError
from ninjemys.packages.discovery import PackageIndex
from ninjemys.tools.cli import entry


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(prog="rosed", description="Edit a file within a ROS package")
    p.add_argument("package")
    p.add_argument("filename")
    args = p.parse_args(argv)
    root = PackageIndex.from_environment().find(args.package).path
    matches = sorted(
        Path(d) / args.filename
        for d, dirs, files in os.walk(root)
        if args.filename in files and not Path(d).name.startswith(".")
    )
    if not matches:
        raise PackageError(f"[rosed] cannot find file [{args.filename}] in package [{args.package}]")
    editor = shlex.split(os.environ.get("EDITOR") or "vim")
    os.execvp(editor[0], [*editor, str(matches[0])])
    return 0


console_main = entry(main)

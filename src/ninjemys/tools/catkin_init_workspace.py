"""``catkin_init_workspace [SRC_DIR]``: write the toplevel CMakeLists.txt of a workspace's src/."""

from __future__ import annotations

import argparse
from pathlib import Path

from ninjemys.errors import PackageError
from ninjemys.packages.builder import TOPLEVEL_CMAKE
from ninjemys.tools.cli import entry


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(prog="catkin_init_workspace", description="Initializes a catkin workspace")
    p.add_argument("workspace", nargs="?", default=".", help="The path to the source space (default: .)")
    args = p.parse_args(argv)
    src = Path(args.workspace).resolve()
    if not src.is_dir():
        raise PackageError(f"Workspace '{src}' does not exist")
    target = src / "CMakeLists.txt"
    if target.exists() or target.is_symlink():
        raise PackageError(f"File '{target}' already exists")
    target.write_text(TOPLEVEL_CMAKE, encoding="utf-8")
    print(f'Creating file "{target}"')
    return 0


console_main = entry(main)

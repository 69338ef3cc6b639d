"""``rosrun PKG EXECUTABLE [ARGS...]``: run an executable of a package (the process replaces rosrun).

Remapping arguments (``chatter:=/x``, ``__name:=n``, ``_param:=v``) are passed through unchanged,
``--prefix 'gdb -ex run --args'`` wraps the command like ROS 1's rosrun. Not-found and
not-executable errors are one line each, the latter with the ``chmod +x`` hint.
"""

from __future__ import annotations

import os
import shlex
import sys

from ninjemys.commands import with_our_commands
from ninjemys.errors import PackageError
from ninjemys.packages.discovery import PackageIndex
from ninjemys.packages.executables import find_executable
from ninjemys.tools.cli import entry

USAGE = "Usage: rosrun [--prefix cmd] [--debug] PACKAGE EXECUTABLE [ARGS]"


def resolve_command(package: str, executable: str, args: list[str]) -> list[str]:
    """The argv that runs ``executable`` of ``package`` (PackageError when it cannot)."""
    manifest = PackageIndex.from_environment().find(package)
    return find_executable(manifest, executable).command(args)


def main(argv: list[str] | None = None) -> int:
    argv = list(sys.argv[1:] if argv is None else argv)
    prefix: list[str] = []
    while argv and argv[0].startswith("--"):
        option = argv.pop(0)
        if option == "--prefix" and argv:
            prefix = shlex.split(argv.pop(0))
        elif option.startswith("--prefix="):
            prefix = shlex.split(option.split("=", 1)[1])
        elif option in ("--debug",):
            continue
        elif option in ("--help", "-h"):
            print(USAGE)
            return 0
        else:
            print(f"[rosrun] unknown option {option}\n{USAGE}", file=sys.stderr)
            return 1
    if len(argv) < 2:
        print(USAGE, file=sys.stderr)
        return 1
    package, executable, rest = argv[0], argv[1], argv[2:]
    try:
        command = prefix + resolve_command(package, executable, rest)
    except PackageError as exc:
        print(f"[rosrun] {exc}", file=sys.stderr)
        return 1
    sys.stdout.flush()
    sys.stderr.flush()
    try:
        os.execvpe(command[0], command, with_our_commands(os.environ))
    except OSError as exc:
        print(f"[rosrun] cannot execute {command[0]}: {exc.strerror}", file=sys.stderr)
        return 1
    return 0


console_main = entry(main)

"""What every command-line tool shares: one-line errors on stderr, exit codes, no tracebacks.

Each tool module defines ``main(argv: list[str] | None = None) -> int`` and exposes
``console_main = entry(main)`` for the console-script entry point in pyproject.
"""

from __future__ import annotations

import os
import sys
from collections.abc import Callable

from ninjemys.errors import MasterUnreachable, NinjemysError

TYPE_CHECKING = False  # importing typing costs ~7 ms of every tool's start-up
if TYPE_CHECKING:
    from typing import Any

    from ninjemys.master.client import MasterClient


def error(message: str) -> None:
    """Print a user-facing error the way ROS 1 tools do (one line, stderr)."""
    print(message if message.startswith("ERROR") else f"ERROR: {message}", file=sys.stderr)


def entry(main: Callable[[list[str] | None], int]) -> Callable[[], None]:
    """Wrap ``main`` for a console script: map our errors and Ctrl-C to exit codes, never a traceback."""

    def console_main() -> None:
        try:
            code = main(sys.argv[1:])
        except KeyboardInterrupt:
            code = 130 if os.environ.get("NINJEMYS_SIGINT_CODE") else 0
        except BrokenPipeError:
            # `rostopic echo /x | head`: the reader went away; exit quietly like ROS 1 tools
            devnull = os.open(os.devnull, os.O_WRONLY)
            os.dup2(devnull, sys.stdout.fileno())
            code = 1
        except MasterUnreachable:
            error("Unable to communicate with master!")
            code = 1
        except NinjemysError as exc:
            error(str(exc))
            code = 1
        sys.exit(code)

    return console_main


def master(caller_id: str = "/ninjemys_tool") -> MasterClient:
    """A master client for a command-line tool (ROS_MASTER_URI), with a short timeout so a hung
    master gives a clear error instead of a hang."""
    from ninjemys.master.client import MasterClient

    return MasterClient(caller_id=caller_id, timeout=10.0)


class _Unused:
    """Stands in for the parser of a subcommand that was not invoked (nothing to build)."""

    def add_argument(self, *args: object, **kwargs: object) -> None:
        return None

    def set_defaults(self, **kwargs: object) -> None:
        return None


class Subcommands:
    """Builds only the invoked subcommand's argparse parser (``matched`` is False for an unknown one).

    argparse spends most of a short tool's start-up building parsers (and their gettext lookups) for
    subcommands the user did not type; ``add`` returns a real parser only for ``command``.
    """

    def __init__(self, prog: str, command: str) -> None:
        import argparse

        self.command = command
        self.matched = False
        self.parser = argparse.ArgumentParser(prog=prog, add_help=False)
        self._sub = self.parser.add_subparsers(dest="command")

    def add(self, name: str, *aliases: str) -> Any:
        if self.command != name and self.command not in aliases:
            return _Unused()
        self.matched = True
        return self._sub.add_parser(self.command, prog=f"{self.parser.prog} {name}")


def run_subcommand(
    argv: list[str],
    usage: str,
    build: Callable[[str], Any],
    prepare: Callable[[list[str]], list[str]] | None = None,
) -> int:
    """Dispatch ``tool <command> [args]``: the usage text for no or an unknown command, else the
    command's ``run(args)``. ``prepare`` may rewrite argv first (e.g. insert ``--`` before YAML values);
    a leading ``--`` left in an ``args`` remainder is dropped."""
    if not argv or argv[0] in ("-h", "--help", "help"):
        print(usage)
        return 0 if argv else 1
    parser = build(argv[0])
    if parser is None:
        print(usage)
        return 1
    args = parser.parse_args(prepare(argv) if prepare is not None else argv)
    rest = getattr(args, "args", None)
    if isinstance(rest, list) and rest[:1] == ["--"]:
        args.args = rest[1:]
    return args.run(args)

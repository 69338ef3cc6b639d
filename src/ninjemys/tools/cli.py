"""What every command-line tool shares: one-line errors on stderr, exit codes, no tracebacks.

``entry`` and ``error`` live in :mod:`ninjemys.commands` (the base layer) so the apps (sim, web, the
gateway) wrap their commands the same way without importing the tools; they are re-exported here.

Each tool module defines ``main(argv: list[str] | None = None) -> int`` and exposes
``console_main = entry(main)`` for the console-script entry point in pyproject.
"""

from __future__ import annotations

from collections.abc import Callable

from ninjemys.commands import entry as entry  # re-exported: every tool takes it from here
from ninjemys.commands import error as error

TYPE_CHECKING = False  # importing typing costs ~7 ms of every tool's start-up
if TYPE_CHECKING:
    from typing import Any

    from ninjemys.master.client import MasterClient


def master(caller_id: str = "/ninjemys_tool") -> MasterClient:
    """A master client for a command-line tool (ROS_MASTER_URI), with a short timeout so a hung
    master gives a clear error instead of a hang."""
    from ninjemys.master.client import MasterClient

    return MasterClient(caller_id=caller_id, timeout=10.0)


def wait_for_master_like_roscpp(node: Any) -> bool:
    """Wait for the master as a roscpp node does (tf_echo, tf_monitor, static_transform_publisher,
    buffer_server are roscpp programs in ROS 1): with no master, roscpp prints one ERROR line and
    retries until it answers, then says it connected. False if the node shut down meanwhile (Ctrl-C).

    This is a poll by nature (a master that is not running sends no event); roscpp retries every
    quarter second too, and the wait ends at once on shutdown.
    """
    import sys
    import time

    from ninjemys.errors import MasterUnreachable
    from ninjemys.net.addresses import split_uri

    host, port = split_uri(node.master_uri)
    failed = False
    while True:
        try:
            node.master.get_pid()
        except MasterUnreachable:
            if not failed:
                sys.stderr.write(
                    f"[ERROR] [{time.time():.9f}]: [registerPublisher] Failed to contact master at "
                    f"[{host}:{port}].  Retrying...\n"
                )
                sys.stderr.flush()
                failed = True
            if node.wait_for_shutdown(0.25):
                return False
            continue
        if failed:
            sys.stdout.write(f"[ INFO] [{time.time():.9f}]: Connected to master at [{host}:{port}]\n")
            sys.stdout.flush()
        return True


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

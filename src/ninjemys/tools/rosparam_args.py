"""rosparam's command line, with ROS 1's usage, help and error texts (rosparam is built on optparse).

Why not argparse: its messages differ from ROS 1's, and importing and building it is ~15 ms of a
~60 ms ``rosparam get``. The everyday forms (``get NAME``, ``list [NS]``, ``dump FILE NS``, ``delete
NAME`` with their ``-p``/``-v`` flags) are read directly. Anything else - ``-h``, an unknown, combined
or long option, ``--``, and every ``set`` (whose YAML values may look like options) - goes to optparse
configured exactly as ROS 1 configures it, so help and errors are optparse's own text. Usage errors
print ``Usage: ...`` and ``rosparam: error: ...`` on stderr and exit with status 2, as in ROS 1.
"""

from __future__ import annotations

TYPE_CHECKING = False  # importing typing costs ~7 ms of a tool's start-up
if TYPE_CHECKING:
    from optparse import OptionParser

PROG = "rosparam"

#: command -> (optparse usage, the flags it takes without a value)
_COMMANDS: dict[str, tuple[str, str]] = {
    "get": ("usage: %prog get [options] parameter", "-p -v"),
    "dump": ("usage: %prog dump [options] file [namespace]", "-v"),
    "set": ("usage: %prog set [options] parameter value", "-v"),
    "load": ("usage: %prog load [options] file [namespace]", "-v"),
    "delete": ("usage: %prog delete [options] parameter", "-v"),
    "list": ("usage: %prog list [namespace]", ""),
}
#: ``rosparam del`` (not in ROS 1) is kept as a spelling of ``delete``
ALIASES = {"del": "delete"}
COMMANDS = frozenset(_COMMANDS) | frozenset(ALIASES)

_NO_NAME = "invalid arguments. Please specify a parameter name"
_TOO_MANY = "too many arguments"


class ParamArgs:
    """One parsed ``rosparam`` command line."""

    __slots__ = ("command", "args", "verbose", "pretty", "textfile", "binfile")

    def __init__(self, command: str) -> None:
        self.command = command
        self.args: list[str] = []
        self.verbose = False
        self.pretty = False
        self.textfile: str | None = None
        self.binfile: str | None = None

    def arg(self, index: int) -> str | None:
        """The ``index``-th positional argument, or None when it was not given."""
        return self.args[index] if index < len(self.args) else None


def build_parser(command: str) -> OptionParser:
    """The optparse parser ROS 1's rosparam builds for ``command`` (same usage, options and help)."""
    from optparse import OptionParser

    parser = OptionParser(usage=_COMMANDS[command][0], prog=PROG)
    if command == "get":
        parser.add_option(
            "-p",
            dest="pretty",
            default=False,
            action="store_true",
            help="pretty print. WARNING: not YAML-safe",
        )
    elif command == "set":
        parser.add_option(
            "-t",
            "--textfile",
            dest="text_file",
            default=None,
            metavar="TEXT_FILE",
            help="set parameters to contents of text file",
        )
        parser.add_option(
            "-b",
            "--binfile",
            dest="bin_file",
            default=None,
            metavar="BINARY_FILE",
            help="set parameters to contents of binary file",
        )
    if command != "list":
        parser.add_option(
            "-v", dest="verbose", default=False, action="store_true", help="turn on verbose output"
        )
    return parser


def usage_error(command: str, message: str) -> None:
    """Print ROS 1's usage and ``rosparam: error: message`` on stderr; exits with status 2."""
    build_parser(ALIASES.get(command, command)).error(message)


def parse(command: str, argv: list[str]) -> ParamArgs:
    """Parse the words after ``rosparam <command>`` (``command`` is one of :data:`COMMANDS`)."""
    command = ALIASES.get(command, command)
    parsed = _parse_simple(command, argv) if command != "set" else None
    if parsed is None:
        parsed = _parse_optparse(command, argv)
    _check_count(parsed)
    return parsed


def _parse_simple(command: str, argv: list[str]) -> ParamArgs | None:
    """Positional words and the command's own flags; None for anything optparse must judge."""
    flags = _COMMANDS[command][1].split()
    parsed = ParamArgs(command)
    for word in argv:
        if word in flags:
            if word == "-p":
                parsed.pretty = True
            else:
                parsed.verbose = True
        elif word == "-" or not word.startswith("-"):
            parsed.args.append(word)
        else:
            return None
    return parsed


def _parse_optparse(command: str, argv: list[str]) -> ParamArgs:
    parser = build_parser(command)
    if command == "set":
        options_argv, positional = _split_set_argv(command, argv)
        options, _ = parser.parse_args(options_argv)
    else:
        options, positional = parser.parse_args(argv)
    parsed = ParamArgs(command)
    parsed.args = list(positional)
    parsed.verbose = bool(getattr(options, "verbose", False))
    parsed.pretty = bool(getattr(options, "pretty", False))
    parsed.textfile = getattr(options, "text_file", None)
    parsed.binfile = getattr(options, "bin_file", None)
    if parsed.textfile and parsed.binfile:
        usage_error(command, "you may only specify one of --textfile or --binfile")
    return parsed


def _split_set_argv(command: str, argv: list[str]) -> tuple[list[str], list[str]]:
    """``rosparam set``'s rule: a word that starts with ``-`` and a digit is a value (a negative
    number), not an option; ``-t``/``-b`` take the next word. Returns (option words, positional)."""
    options: list[str] = []
    positional: list[str] = []
    wants_value = False
    for word in argv:
        if word.startswith("-"):
            if word in ("-t", "--textfile", "-b", "--binfile"):
                wants_value = True
                options.append(word)
            elif wants_value:
                usage_error(command, "-t and --textfile options require an argument")
            elif len(word) > 1 and "0" <= word[1] <= "9":
                positional.append(word)
            else:
                options.append(word)
        elif wants_value:
            wants_value = False
            options.append(word)
        else:
            positional.append(word)
    return options, positional


def _check_count(parsed: ParamArgs) -> None:
    count, command = len(parsed.args), parsed.command
    if command == "list":
        if count > 1:
            usage_error(command, _TOO_MANY)
    elif command in ("get", "delete"):
        if count == 0:
            usage_error(command, _NO_NAME)
        elif count > 1:
            usage_error(command, _TOO_MANY)
    elif command == "dump":
        if count > 2:
            usage_error(command, _TOO_MANY)
    elif command == "load":
        if count == 0:
            usage_error(command, "invalid arguments. Please specify a file name or - for stdin")
        elif count > 2:
            usage_error(command, _TOO_MANY)
    elif count == 0:  # set
        usage_error(command, _NO_NAME)
    elif count == 1 and not (parsed.textfile or parsed.binfile):
        usage_error(command, "invalid arguments. Please specify a parameter value")
    elif count > 2:
        usage_error(command, _TOO_MANY)


__all__ = ["ALIASES", "COMMANDS", "PROG", "ParamArgs", "build_parser", "parse", "usage_error"]

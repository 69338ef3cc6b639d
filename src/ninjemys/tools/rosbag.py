"""``rosbag``: record, play, info, filter, reindex, compress, decompress, check, export.

Thin: option parsing and output here, the work in ``ninjemys.bag``. Option names and output follow
ROS 1's rosbag; ``export --mcap`` is beyond ROS 1.
"""

from __future__ import annotations

import argparse
import ast
import logging
import os
import shutil
import sys
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from typing import Any

from ninjemys.bag.format import DEFAULT_CHUNK_THRESHOLD, NSEC
from ninjemys.bag.info import info_key, info_text, info_yaml
from ninjemys.bag.ops import check_bag, copy_bag, uncompressed_size
from ninjemys.bag.progress import Progress
from ninjemys.bag.reader import BagReader
from ninjemys.bag.reindex import reindex_in_place
from ninjemys.errors import BagError, NinjemysError
from ninjemys.tools.cli import entry, error

COMMANDS = {
    "check": "Determine whether a bag is playable in the current system, or if it can be migrated.",
    "compress": "Compress one or more bag files.",
    "decompress": "Decompress one or more bag files.",
    "export": "Export a bag file to another format (--mcap OUT.mcap).",
    "filter": "Filter the contents of the bag.",
    "info": "Summarize the contents of one or more bag files.",
    "play": "Play back the contents of one or more bag files in a time-synchronized fashion.",
    "record": "Record a bag file with the contents of specified topics.",
    "reindex": "Reindexes one or more bag files.",
}


class _Parser(argparse.ArgumentParser):
    """argparse that reports usage errors as one ``ERROR:`` line with exit code 2."""

    def error(self, message: str) -> None:  # type: ignore[override]
        self.print_usage(sys.stderr)
        error(message)
        raise SystemExit(2)


def _usage() -> str:
    lines = [
        "Usage: rosbag <subcommand> [options] [args]",
        "",
        "A bag is a file format in ROS for storing ROS message data. The rosbag command can record, replay and manipulate bags.",
        "",
        "Available subcommands:",
    ]
    lines += [f"   {name}  " for name in sorted(COMMANDS)]
    lines += ["", "For additional information, see http://wiki.ros.org/rosbag", ""]
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    argv = list(sys.argv[1:] if argv is None else argv)
    if not argv or argv[0] in ("-h", "--help", "help"):
        if len(argv) > 1 and argv[1] in COMMANDS:
            return main([argv[1], "-h"])
        print(_usage())
        return 0
    _route_library_warnings()
    cmd, rest = argv[0], argv[1:]
    handler = _HANDLERS.get(cmd)
    if handler is None:
        error(f"Unknown command: '{cmd}'")
        print(_usage(), file=sys.stderr)
        return 1
    try:
        return handler(rest)
    except SystemExit as exc:
        return int(exc.code or 0) if not isinstance(exc.code, str) else 1


class _Once(logging.Filter):
    """Let each distinct warning through once (a bag opened twice must not warn twice)."""

    def __init__(self) -> None:
        super().__init__()
        self.seen: set[str] = set()

    def filter(self, record: logging.LogRecord) -> bool:
        text = record.getMessage()
        if text in self.seen:
            return False
        self.seen.add(text)
        return True


def _route_library_warnings() -> None:
    """Bag damage found by the library reaches the user as ``WARNING: ...`` lines on stderr."""
    logger = logging.getLogger("ninjemys.bag")
    if any(getattr(h, "_rosbag_tool", False) for h in logger.handlers):
        return
    handler = logging.StreamHandler(sys.stderr)
    handler.setFormatter(logging.Formatter("WARNING: %(message)s"))
    handler.addFilter(_Once())
    handler._rosbag_tool = True  # type: ignore[attr-defined]
    logger.addHandler(handler)
    logger.propagate = False


# -- info ---------------------------------------------------------------------------------------


def info_cmd(argv: list[str]) -> int:
    p = _Parser(
        prog="rosbag info",
        usage="rosbag info [options] BAGFILE1 [BAGFILE2 BAGFILE3 ...]",
        description=COMMANDS["info"],
    )
    p.add_argument("-y", "--yaml", action="store_true", help="print information in YAML format")
    p.add_argument("-k", "--key", default=None, help="print information on the given key")
    p.add_argument("--freq", action="store_true", help="display topic message frequency statistics")
    p.add_argument("bags", nargs="*")
    opts = p.parse_intermixed_args(argv)
    if not opts.bags:
        p.error("You must specify at least 1 bag file.")
    if opts.key and not opts.yaml:
        p.error("You can only specify key when printing in YAML format.")
    for i, name in enumerate(opts.bags):
        try:
            with BagReader(name) as reader:
                if opts.yaml:
                    text = info_yaml(reader, name, opts.freq)
                    if opts.key:
                        value = info_key(text, opts.key)
                        if value is None:
                            print(f'Error getting key "{opts.key}"', file=sys.stderr)
                        else:
                            print(value)
                    else:
                        print(text)
                else:
                    print(info_text(reader, name, opts.freq))
        except BagError as exc:
            error(f"reading {name}: {exc}")
            return 1
        if i < len(opts.bags) - 1:
            print("---")
    return 0


# -- filter -------------------------------------------------------------------------------------


def filter_cmd(argv: list[str]) -> int:
    p = _Parser(
        prog="rosbag filter",
        usage="rosbag filter [options] INBAG OUTBAG EXPRESSION",
        description="Filter the contents of the bag. EXPRESSION can be any Python-legal expression over "
        "topic (name of topic), m (message) and t (time of message: t.secs, t.nsecs).",
    )
    p.add_argument("-p", "--print", dest="verbose_pattern", default=None, metavar="PRINT-EXPRESSION")
    p.add_argument("args", nargs="*")
    opts = p.parse_args(argv)
    if len(opts.args) < 3:
        p.error(
            [
                "You must specify an in bag, an out bag, and an expression.",
                "You must specify an out bag and an expression.",
                "You must specify an expression.",
            ][len(opts.args)]
        )
    if len(opts.args) > 3:
        p.error("Too many arguments.")
    inbag, outbag, expr = opts.args
    if not os.path.isfile(inbag):
        error(f"Cannot locate input bag file [{inbag}]")
        return 2
    if os.path.realpath(inbag) == os.path.realpath(outbag):
        error(f"Cannot use same file as input and output [{inbag}]")
        return 3
    predicate = _compile_expression(expr, "EXPRESSION")
    printer = _compile_expression(opts.verbose_pattern, "PRINT-EXPRESSION") if opts.verbose_pattern else None

    from ninjemys.bag.api import _Decoders
    from ninjemys.rostime import Time

    decoders = _Decoders()
    # expressions over topic and t alone never pay for deserialization
    needs_m = _uses_name(expr, "m") or (
        opts.verbose_pattern is not None and _uses_name(opts.verbose_pattern, "m")
    )

    def keep(msg: Any) -> bool:
        conn = msg.connection
        m = None
        if needs_m:
            try:
                m = decoders.get(conn)().deserialize(bytes(msg.data))
            except NinjemysError:
                raise
            except Exception as exc:  # bytes from the file that do not decode
                raise BagError(f"{conn.topic} ({conn.datatype}): cannot deserialize: {exc}") from None
        t = Time(*divmod(msg.time, NSEC))
        try:
            match = bool(predicate(conn.topic, m, t))
            if printer is not None:
                print("MATCH" if match else "NO MATCH", printer(conn.topic, m, t))
        except Exception as exc:  # the user's expression: report it, do not crash
            raise BagError(
                f"filter expression failed on {conn.topic} at {t}: {type(exc).__name__}: {exc}"
            ) from None
        return match

    with BagReader(inbag) as reader:
        total = uncompressed_size(reader)
        compression = _dominant_compression(reader)
    copy_bag(Path(inbag), Path(outbag), compression, keep, Progress(outbag, total))
    return 0


def _compile_expression(expr: str, what: str) -> Callable:
    try:
        return eval(f"lambda topic, m, t: ({expr})")  # noqa: S307 - rosbag filter evaluates user Python by design
    except SyntaxError as exc:
        raise BagError(f"{what} is not a valid Python expression: {expr!r} ({exc.msg})") from None


def _uses_name(expr: str, name: str) -> bool:
    return any(
        isinstance(node, ast.Name) and node.id == name for node in ast.walk(ast.parse(expr, mode="eval"))
    )


def _dominant_compression(reader: BagReader) -> str:
    counts: dict[str, int] = {}
    for header in reader.chunk_headers.values():
        counts[header.compression] = counts.get(header.compression, 0) + 1
    return max(counts, key=lambda k: counts[k]) if counts else "none"


# -- reindex / compress / decompress ------------------------------------------------------------


def _bag_op_parser(name: str, compress_flags: bool) -> _Parser:
    p = _Parser(
        prog=f"rosbag {name}",
        usage=f"rosbag {name} [options] BAGFILE1 [BAGFILE2 ...]",
        description=COMMANDS[name],
    )
    p.add_argument("--output-dir", metavar="DIR", help="write to directory DIR")
    p.add_argument("-f", "--force", action="store_true", help="force overwriting of backup file if it exists")
    p.add_argument("-q", "--quiet", action="store_true", help="suppress noncritical messages")
    if compress_flags:
        p.add_argument(
            "-j",
            "--bz2",
            dest="compression",
            action="store_const",
            const="bz2",
            default="bz2",
            help="use BZ2 compression",
        )
        p.add_argument(
            "--lz4", dest="compression", action="store_const", const="lz4", help="use lz4 compression"
        )
    p.add_argument("bags", nargs="*")
    return p


def _bag_op(
    bags: list[str],
    output_dir: str | None,
    force: bool,
    quiet: bool,
    op: Callable[[Path, Path], None],
    in_place_copy: bool,
) -> int:
    """ROS 1's bag_op: each bag is rewritten in place (the original kept as NAME.orig.bag) or into DIR."""
    status = 0
    for name in bags:
        src = Path(name)
        if not src.is_file():
            error(f"reading {name}: no such file")
            status = 1
            continue
        if output_dir is None:
            stem, ext = os.path.splitext(name)
            backup = Path(f"{stem}.orig{ext}")
            if backup.exists() and not force:
                if not quiet:
                    print(f"Skipping {name}. Backup path {backup} already exists.", file=sys.stderr)
                continue
            try:
                if in_place_copy:
                    shutil.copy(src, backup)
                else:
                    os.replace(src, backup)
            except OSError as exc:
                error(f"{'copying' if in_place_copy else 'moving'} {name} to {backup}: {exc.strerror}")
                status = 1
                continue
            source, target = backup, src
        else:
            target = Path(output_dir) / src.name
            source = src
            if in_place_copy:
                shutil.copy(src, target)
        try:
            op(source, target)
        except KeyboardInterrupt:
            if output_dir is None and not in_place_copy:
                os.replace(source, src)
            raise
        except NinjemysError as exc:
            error(f"operating on {source}: {exc}")
            if output_dir is None and not in_place_copy:
                os.replace(source, src)
            status = 1
    return status


def reindex_cmd(argv: list[str]) -> int:
    opts = _bag_op_parser("reindex", False).parse_intermixed_args(argv)
    if not opts.bags:
        _bag_op_parser("reindex", False).error("You must specify at least one bag file.")

    def op(source: Path, target: Path) -> None:
        size = target.stat().st_size
        progress = None if opts.quiet else Progress(str(target), size)
        for offset in reindex_in_place(target):
            if progress is not None:
                progress.step(offset)
        if progress is not None:
            progress.finish()

    return _bag_op(opts.bags, opts.output_dir, opts.force, opts.quiet, op, in_place_copy=True)


def _compression_cmd(name: str, argv: list[str]) -> int:
    parser = _bag_op_parser(name, name == "compress")
    opts = parser.parse_intermixed_args(argv)
    if not opts.bags:
        parser.error("You must specify at least one bag file.")
    compression = opts.compression if name == "compress" else "none"

    def op(source: Path, target: Path) -> None:
        with BagReader(source) as reader:
            total = uncompressed_size(reader)
        copy_bag(source, target, compression, progress=None if opts.quiet else Progress(str(target), total))

    return _bag_op(opts.bags, opts.output_dir, opts.force, opts.quiet, op, in_place_copy=False)


def compress_cmd(argv: list[str]) -> int:
    return _compression_cmd("compress", argv)


def decompress_cmd(argv: list[str]) -> int:
    return _compression_cmd("decompress", argv)


# -- check / export -----------------------------------------------------------------------------


def check_cmd(argv: list[str]) -> int:
    p = _Parser(prog="rosbag check", usage="rosbag check BAG", description=COMMANDS["check"])
    p.add_argument("bag", nargs="?")
    opts = p.parse_args(argv)
    if not opts.bag:
        p.error("You must specify a bag file to check.")
    problems = check_bag(Path(opts.bag))
    if problems:
        for problem in problems:
            error(problem)
        return 1
    print("Bag file does not need any migrations.")
    return 0


def export_cmd(argv: list[str]) -> int:
    p = _Parser(
        prog="rosbag export", usage="rosbag export --mcap OUT.mcap BAGFILE", description=COMMANDS["export"]
    )
    p.add_argument("--mcap", metavar="OUT.mcap", required=True, help="write an MCAP file (ros1msg schemas)")
    p.add_argument("-q", "--quiet", action="store_true", help="suppress the progress bar")
    p.add_argument("bag")
    opts = p.parse_args(argv)
    from ninjemys.bag.mcap import export_mcap

    with BagReader(opts.bag) as reader:
        total = uncompressed_size(reader)
    count = export_mcap(Path(opts.bag), Path(opts.mcap), None if opts.quiet else Progress(opts.mcap, total))
    if not opts.quiet:
        print(f"Exported {count} messages to {opts.mcap}", file=sys.stderr)
    return 0


# -- record / play ------------------------------------------------------------------------------


def record_cmd(argv: list[str]) -> int:
    from ninjemys.bag.record import record_main

    return record_main(argv, _Parser)


def play_cmd(argv: list[str]) -> int:
    from ninjemys.bag.play import play_main

    return play_main(argv, _Parser)


_HANDLERS: dict[str, Callable[[list[str]], int]] = {
    "check": check_cmd,
    "compress": compress_cmd,
    "decompress": decompress_cmd,
    "export": export_cmd,
    "filter": filter_cmd,
    "info": info_cmd,
    "play": play_cmd,
    "record": record_cmd,
    "reindex": reindex_cmd,
}

console_main = entry(main)

__all__ = ["main", "console_main", "DEFAULT_CHUNK_THRESHOLD"]

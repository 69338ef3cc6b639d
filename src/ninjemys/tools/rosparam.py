"""``rosparam``: list, get, set, load, dump and delete parameters, with ROS 1's output.

Values travel as YAML on the command line and in files (rosparam's dialect: ``!!binary``,
``!degrees``/``!radians`` and ``rad()``/``deg()`` angles); printing follows real rosparam (PyYAML
block style, the ``...`` document end stripped from scalars).
"""

from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path
from typing import Any

from ninjemys import names
from ninjemys.errors import MasterError, MasterUnreachable, ParameterError
from ninjemys.paramyaml import ParamYamlError, dump_yaml, load_yaml
from ninjemys.tools.cli import Subcommands, entry, master, run_subcommand

NAME = "rosparam"
USAGE = """rosparam is a command-line tool for getting, setting, and deleting parameters from the ROS Parameter Server.

Commands:
\trosparam set\tset parameter
\trosparam get\tget parameter
\trosparam load\tload parameters from file
\trosparam dump\tdump parameters to file
\trosparam delete\tdelete parameter
\trosparam list\tlist parameter names
"""


def _caller_id() -> str:
    return f"/rosparam-{os.getpid()}"


def _resolve(param: str) -> str:
    """Resolve a user-typed name the way rosparam does: relative to ROS_NAMESPACE."""
    ns = names.get_ros_namespace()
    if param in ("", "/"):
        return "/"
    if names.is_private(param):
        raise ParameterError(f"private names are not allowed here: [{param}]")
    return names.resolve_name(param, ns + "rosparam")


def _print_value(value: Any, pretty: bool) -> None:
    if pretty and isinstance(value, dict):
        _pretty_print(value, "")
    elif pretty and isinstance(value, str):
        print(value)
    else:
        text = dump_yaml(value)
        if text.endswith("\n...\n"):
            text = text[:-4]
        sys.stdout.write(text + "\n")


def _pretty_print(value: dict[str, Any], indent: str) -> None:
    for key, item in sorted(value.items()):
        if isinstance(item, dict):
            print(f"{indent}{key}:")
            _pretty_print(item, indent + "  ")
        elif isinstance(item, str):
            if "\n" in item:
                print(f"{indent}{key}: |")
                for line in item.split("\n"):
                    print(f"{indent}  {line}")
            else:
                print(f"{indent}{key}: {item}")
        else:
            text = dump_yaml(item)
            if text.endswith("\n...\n"):
                text = text[:-4]
            sys.stdout.write(f"{indent}{key}: {text}")


def _set_tree(client: Any, param: str, value: Any, verbose: bool) -> None:
    """rosparam's set: a dict updates key by key (it does not replace the subtree)."""
    if isinstance(value, dict):
        for key, item in value.items():
            if not isinstance(key, str):
                raise ParameterError(
                    f"YAML dictionaries must have string keys. Invalid dictionary is:\n{value}"
                )
            _set_tree(client, names.ns_join(param, key), item, verbose)
        return
    client.set_param(param, value)
    if verbose:
        print(f"set parameter [{param}] to [{value}]")


def _cmd_list(args: argparse.Namespace) -> int:
    ns = names.make_global_ns(_resolve(args.namespace) if args.namespace else "/")
    for name in sorted(master(_caller_id()).get_param_names()):
        if name.startswith(ns) or ns == "/":
            print(name)
    return 0


def _cmd_get(args: argparse.Namespace) -> int:
    param = _resolve(args.parameter)
    if args.verbose:
        print(f"getting parameter [{param}]")
    try:
        value = master(_caller_id()).get_param(param)
    except MasterUnreachable:
        raise
    except MasterError as exc:
        raise ParameterError(f"Parameter [{param}] is not set") from exc
    _print_value(value, args.pretty)
    return 0


def _cmd_set(args: argparse.Namespace) -> int:
    param = _resolve(args.parameter)
    client = master(_caller_id())
    if args.textfile:
        value: Any = Path(args.textfile).read_text()
    elif args.binfile:
        value = Path(args.binfile).read_bytes()
    else:
        if args.value is None:
            raise ParameterError("rosparam set: missing value (use -t FILE or -b FILE, or give a YAML value)")
        value = _load(args.value, "command line")
    _set_tree(client, param, value, args.verbose)
    return 0


def _load(text: str, where: str) -> Any:
    try:
        return load_yaml(text)
    except ParamYamlError as exc:
        raise ParameterError(f"invalid YAML in {where}: {exc}") from None


def _cmd_load(args: argparse.Namespace) -> int:
    ns = _resolve(args.namespace) if args.namespace else names.get_ros_namespace()
    if args.file == "-":
        text, where = sys.stdin.read(), "stdin"
    else:
        path = Path(args.file)
        if not path.is_file():
            raise ParameterError(f"file does not exist [{args.file}]")
        text, where = path.read_text(), str(path)
    if args.verbose:
        print(f"reading parameters from [{where}]")
    docs = _load_all(text, where)
    client = master(_caller_id())
    for doc in docs:
        if doc is None:
            continue
        target = ns
        if isinstance(doc, dict) and "_ns" in doc:
            target = names.ns_join(ns, str(doc.pop("_ns")))
        if target == "/" and not isinstance(doc, dict):
            raise ParameterError(f"{where}: global / can only be set to a dictionary")
        _set_tree(client, target.rstrip("/") or "/", doc, args.verbose)
    return 0


def _load_all(text: str, where: str) -> list[Any]:
    from ninjemys.paramyaml import load_yaml_documents

    try:
        return load_yaml_documents(text)
    except ParamYamlError as exc:
        raise ParameterError(f"invalid YAML in {where}: {exc}") from None


def _cmd_dump(args: argparse.Namespace) -> int:
    ns = _resolve(args.namespace) if args.namespace else names.get_ros_namespace().rstrip("/") or "/"
    tree = master(_caller_id()).get_param(ns)
    if args.verbose:
        print(f"dumping namespace [{ns}] to file [{args.file}]")
    text = dump_yaml(tree)
    if args.file in (None, "-"):
        sys.stdout.write(text)
    else:
        Path(args.file).write_text(text)
    return 0


def _cmd_delete(args: argparse.Namespace) -> int:
    param = _resolve(args.parameter)
    client = master(_caller_id())
    if param == "/":
        client.set_param("/", {})
        if args.verbose:
            print("deleted ENTIRE parameter server")
        return 0
    try:
        client.delete_param(param)
    except MasterUnreachable:
        raise
    except MasterError as exc:
        raise ParameterError(f"parameter [{param}] is not set") from exc
    if args.verbose:
        print(f"deleted parameter [{param}]")
    return 0


def _parser(command: str) -> argparse.ArgumentParser | None:
    sub = Subcommands(NAME, command)
    p = sub.add("list")
    p.add_argument("namespace", nargs="?")
    p.add_argument("-v", dest="verbose", action="store_true")
    p.set_defaults(run=_cmd_list)
    p = sub.add("get")
    p.add_argument("parameter")
    p.add_argument("-p", dest="pretty", action="store_true", help="pretty print. WARNING: not YAML-safe")
    p.add_argument("-v", dest="verbose", action="store_true")
    p.set_defaults(run=_cmd_get)
    p = sub.add("set")
    p.add_argument("parameter")
    p.add_argument("value", nargs="?")
    p.add_argument("-t", "--textfile", help="set parameters to contents of text file")
    p.add_argument("-b", "--binfile", help="set parameters to contents of binary file")
    p.add_argument("-v", dest="verbose", action="store_true")
    p.set_defaults(run=_cmd_set)
    p = sub.add("load")
    p.add_argument("file")
    p.add_argument("namespace", nargs="?")
    p.add_argument("-v", dest="verbose", action="store_true")
    p.set_defaults(run=_cmd_load)
    p = sub.add("dump")
    p.add_argument("file", nargs="?")
    p.add_argument("namespace", nargs="?")
    p.add_argument("-v", dest="verbose", action="store_true")
    p.set_defaults(run=_cmd_dump)
    p = sub.add("delete", "del")
    p.add_argument("parameter")
    p.add_argument("-v", dest="verbose", action="store_true")
    p.set_defaults(run=_cmd_delete)
    return sub.parser if sub.matched else None


def main(argv: list[str] | None = None) -> int:
    return run_subcommand(sys.argv[1:] if argv is None else argv, USAGE, _parser, _protect_negative_numbers)


def _protect_negative_numbers(argv: list[str]) -> list[str]:
    if len(argv) >= 3 and argv[0] == "set" and _is_number(argv[-1]) and argv[-1].startswith("-"):
        return [*argv[:-1], "--", argv[-1]] if "--" not in argv else argv
    return argv


def _is_number(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True


console_main = entry(main)

__all__ = ["main", "console_main"]

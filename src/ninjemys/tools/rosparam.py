"""``rosparam``: list, get, set, load, dump and delete parameters, with ROS 1's output.

Values travel as YAML on the command line and in files (rosparam's dialect: ``!!binary``,
``!degrees``/``!radians`` and ``rad()``/``deg()`` angles); printing follows real rosparam (PyYAML
block style, the ``...`` document end stripped from scalars). The command line, its usage texts and
errors are ROS 1's too (:mod:`ninjemys.tools.rosparam_args`). ``get`` and ``list`` import neither
PyYAML nor an argument-parsing library: start-up time is most of what these commands cost.
"""

from __future__ import annotations

import os
import sys

from ninjemys import names
from ninjemys.errors import MasterError, MasterUnreachable, ParameterError
from ninjemys.paramyaml import ParamYamlError, dump_yaml, load_yaml
from ninjemys.tools import rosparam_args
from ninjemys.tools.cli import entry, master

TYPE_CHECKING = False  # importing typing costs ~7 ms of a tool's start-up
if TYPE_CHECKING:
    from typing import Any

    from ninjemys.tools.rosparam_args import ParamArgs

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
            text = text[:-5]  # a plain scalar: ROS 1 drops the document end and its line break
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


def _cmd_list(args: ParamArgs) -> int:
    namespace = args.arg(0)
    ns = names.make_global_ns(_resolve(namespace) if namespace else "/")
    for name in sorted(master(_caller_id()).get_param_names()):
        if name.startswith(ns) or ns == "/":
            print(name)
    return 0


def _cmd_get(args: ParamArgs) -> int:
    param = _resolve(args.args[0])
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


def _cmd_set(args: ParamArgs) -> int:
    param = _resolve(args.args[0])
    value: Any
    if args.textfile:
        if not os.path.isfile(args.textfile):
            rosparam_args.usage_error("set", f"file '{args.textfile}' does not exist")
        value = _read(args.textfile, "r")
    elif args.binfile:
        value = _read(args.binfile, "rb")
    else:
        text = args.args[1]
        # as in ROS 1: '' cannot be typed as YAML on a command line, so it sets the empty string
        value = "" if text == "" else _load(text, "command line")
    _set_tree(master(_caller_id()), param, value, args.verbose)
    return 0


def _read(path: str, mode: str) -> Any:
    try:
        with open(path, mode) as handle:
            return handle.read()
    except OSError as exc:
        raise ParameterError(f"cannot read [{path}]: {exc.strerror}") from None


def _load(text: str, where: str) -> Any:
    try:
        return load_yaml(text)
    except ParamYamlError as exc:
        raise ParameterError(f"invalid YAML in {where}: {exc}") from None


def _cmd_load(args: ParamArgs) -> int:
    file, namespace = args.args[0], args.arg(1)
    ns = _resolve(namespace) if namespace else names.get_ros_namespace()
    if file == "-":
        text, where = sys.stdin.read(), "stdin"
    else:
        if not os.path.isfile(file):
            raise ParameterError(f"file does not exist [{file}]")
        text, where = _read(file, "r"), file
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


def _cmd_dump(args: ParamArgs) -> int:
    file, namespace = args.arg(0), args.arg(1)
    ns = _resolve(namespace) if namespace else names.get_ros_namespace().rstrip("/") or "/"
    tree = master(_caller_id()).get_param(ns)
    if args.verbose:
        print(f"dumping namespace [{ns}] to file [{file}]")
    text = dump_yaml(tree)
    if not file or file == "-":  # ROS 1 prints for no (or an empty) file name; "-" is ours
        sys.stdout.write(text)
    else:
        try:
            with open(file, "w") as handle:
                handle.write(text)
        except OSError as exc:
            raise ParameterError(f"cannot write [{file}]: {exc.strerror}") from None
    return 0


def _cmd_delete(args: ParamArgs) -> int:
    param = _resolve(args.args[0])
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


_RUN = {
    "list": _cmd_list,
    "get": _cmd_get,
    "set": _cmd_set,
    "load": _cmd_load,
    "dump": _cmd_dump,
    "delete": _cmd_delete,
}


def main(argv: list[str] | None = None) -> int:
    """``rosparam <command> ...``; no or an unknown command prints the command list (exit 0, as ROS 1)."""
    argv = sys.argv[1:] if argv is None else argv
    if not argv or argv[0] not in rosparam_args.COMMANDS:
        print(USAGE)
        return 0
    args = rosparam_args.parse(argv[0], argv[1:])
    return _RUN[args.command](args)


console_main = entry(main)

__all__ = ["main", "console_main"]

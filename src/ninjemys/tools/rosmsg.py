"""``rosmsg`` and ``rossrv``: show, md5, list, package and packages for interface types.

The output is ROS 1's, byte for byte: ``show`` prints the parsed definition (constants first, every
field as ``type name`` with nested message types expanded below it, indented by two spaces), ``show -r``
the file text as written, ``md5`` the md5sum; a type given without its package is searched in every
package (alphabetically) and each match is printed under a ``[pkg/Type]:`` line.

Both commands share this module; ``rossrv`` is the same code in service mode
(:mod:`ninjemys.tools.rossrv` re-exports it for ``python -m``).
"""

from __future__ import annotations

import argparse
import os
import sys
from collections.abc import Callable

from ninjemys.errors import DefinitionError, TypeNotFoundError
from ninjemys.idl import loader, search
from ninjemys.idl.fulltext import split_full_text
from ninjemys.idl.parser import ACTION_SUFFIXES, parse_message
from ninjemys.idl.spec import MsgSpec
from ninjemys.tools.cli import entry, error

MODES = {"msg": ("Message", "message type"), "srv": ("Service", "service type")}


def usage(mode: str) -> str:
    cmd = f"ros{mode}"
    kind = MODES[mode][0]
    lower = kind.lower()
    return (
        f"{cmd} is a command-line tool for displaying information about ROS {kind} types.\n\n"
        "Commands:\n"
        f"\t{cmd} show\tShow {lower} description\n"
        f"\t{cmd} info\tAlias for {cmd} show\n"
        f"\t{cmd} list\tList all {lower}s\n"
        f"\t{cmd} md5\tDisplay {lower} md5sum\n"
        f"\t{cmd} package\tList {lower}s in a package\n"
        f"\t{cmd} packages\tList packages that contain {lower}s\n\n"
        f"Type {cmd} <command> -h for more detailed usage\n"
    )


def spec_to_str(spec: MsgSpec, indent: str = "") -> str:
    """The parsed form rosmsg prints: constants, then fields with nested types expanded."""
    out = [f"{indent}{c.type} {c.name}={c.value_text}\n" for c in spec.constants]
    for f in spec.fields:
        out.append(f"{indent}{f.type} {f.name}\n")
        if f.type.is_message:
            out.append(spec_to_str(loader.get_message_spec(f.type.base), indent + "  "))
    return "".join(out)


def msg_text(type_name: str, raw: bool = False) -> str:
    spec = loader.get_message_spec(type_name)
    return spec.text if raw else spec_to_str(spec)


def srv_text(type_name: str, raw: bool = False) -> str:
    spec = loader.get_service_spec(type_name)
    if raw:
        return spec.text
    return spec_to_str(spec.request) + "---\n" + spec_to_str(spec.response)


def _types_in(package: search.Package, mode: str) -> list[str]:
    """The package's types of this mode; messages include the seven each ``.action`` generates.

    A built ROS 1 package has those seven as ``.msg`` files in its share directory (genaction writes
    them at build time), so real rosmsg lists them with the others; ours come from the ``.action`` file.
    """
    names = set(package.definitions(mode))
    if mode == "msg":
        for stem in package.definitions("action"):
            names.update(f"{stem}{suffix}" for suffix in ACTION_SUFFIXES)
    return sorted(names)


def _packages_with(mode: str) -> list[search.Package]:
    dirs = (mode, "action") if mode == "msg" else (mode,)
    return [
        p
        for _, p in sorted(search.packages().items())
        if any(os.path.isdir(os.path.join(p.path, d)) for d in dirs)
    ]


def _search_bare(mode: str, short: str) -> list[str]:
    return [f"{p.name}/{short}" for p in _packages_with(mode) if short in _types_in(p, mode)]


def _one_arg(parser: argparse.ArgumentParser, args: list[str], what: str) -> str:
    if len(args) > 1:
        parser.error(f"you may only specify one {what}")
    if args:
        return args[0]
    line = ""
    while not line:  # like ROS 1: read the argument from a pipe
        read = sys.stdin.readline()
        if not read:
            parser.error(f"no {what} given")
        line = read.strip()
    return line


def _cmd_show(mode: str, argv: list[str], alias: str) -> int:
    what = MODES[mode][1]
    parser = argparse.ArgumentParser(prog=f"ros{mode} {alias}", usage=f"ros{mode} {alias} [options] <{what}>")
    parser.add_argument("-r", "--raw", action="store_true", help="show raw message text, including comments")
    parser.add_argument("-b", "--bag", metavar="BAGFILE", help="show message from .bag file")
    parser.add_argument("args", nargs="*")
    options = parser.parse_args(argv)
    arg = _one_arg(parser, options.args, what)
    if arg.endswith("." + mode):
        arg = arg[: -len(mode) - 1]
    if "::" in arg:
        parser.error(
            f"ros{mode} does not understand C++-style namespaces (i.e. '::').\n"
            "Please refer to msg/srv types as 'package_name/Type'."
        )
    if "." in arg:
        parser.error(f"invalid message type '{arg}'.\nPlease refer to msg/srv types as 'package_name/Type'.")
    text: Callable[[str, bool], str] = msg_text if mode == "msg" else srv_text
    if options.bag:
        return _show_from_bag(options.bag, arg, options.raw)
    if "/" in arg:
        try:
            print(text(arg, options.raw))
        except (TypeNotFoundError, DefinitionError) as exc:
            error(f"Unable to load {mode} [{arg}]: {exc}")
            return 1
        return 0
    found = _search_bare(mode, arg)
    if not found:
        error(f"Could not find {mode} '{arg}'")
        return 1
    for name in found:
        print(f"[{name}]:")
        print(text(name, options.raw))
    return 0


def _show_from_bag(path: str, type_name: str, raw: bool) -> int:
    """``show -b``: the definition a bag recorded for ``type_name`` (the type need not be installed)."""
    from ninjemys.bag.api import Bag

    with Bag(path) as bag:
        for _topic, raw_msg, _t in bag.read_messages(raw=True):
            datatype, _data, md5sum, _pos, _pytype = raw_msg
            if datatype != type_name:
                continue
            cls = loader.message_class_from_definition(type_name, _pytype._full_text, md5sum)
            print(cls._full_text if raw else _definition_to_str(type_name, cls._full_text))
            return 0
    error(f"no message of type {type_name} in {path}")
    return 1


def _definition_to_str(type_name: str, full_text: str) -> str:
    """spec_to_str over the types embedded in a message definition text."""
    specs = {name: parse_message(text, name) for name, text in split_full_text(type_name, full_text).items()}

    def render(spec: MsgSpec, indent: str) -> str:
        out = [f"{indent}{c.type} {c.name}={c.value_text}\n" for c in spec.constants]
        for f in spec.fields:
            out.append(f"{indent}{f.type} {f.name}\n")
            if f.type.is_message:
                sub = specs.get(f.type.base) or loader.get_message_spec(f.type.base)
                out.append(render(sub, indent + "  "))
        return "".join(out)

    return render(specs[type_name], "")


def _cmd_md5(mode: str, argv: list[str]) -> int:
    what = MODES[mode][1]
    parser = argparse.ArgumentParser(prog=f"ros{mode} md5", usage=f"ros{mode} md5 <{what}>")
    parser.add_argument("args", nargs="*")
    arg = _one_arg(parser, parser.parse_args(argv).args, what)
    get = loader.get_message_class if mode == "msg" else loader.get_service_class
    if "/" in arg:
        try:
            print(get(arg)._md5sum)
        except (TypeNotFoundError, DefinitionError) as exc:
            error(f"Cannot locate [{arg}]: {exc}")
            return 1
        return 0
    matches = _search_bare(mode, arg)
    for name in matches:
        print(f"[{name}]: {get(name)._md5sum}")
    if not matches:
        error(f"No messages matching the name [{arg}]")
        return 1
    return 0


def _cmd_package(mode: str, argv: list[str]) -> int:
    parser = argparse.ArgumentParser(prog=f"ros{mode} package", usage=f"ros{mode} package <package>")
    parser.add_argument(
        "-s", dest="single_line", action="store_true", help=f"list all {mode}s on a single line"
    )
    parser.add_argument("args", nargs="*")
    options = parser.parse_args(argv)
    name = _one_arg(parser, options.args, "package")
    try:
        package = search.find_package(name)
    except TypeNotFoundError as exc:
        error(f"Invalid package: {exc}")
        return 1
    joiner = " " if options.single_line else "\n"
    print(joiner.join(f"{name}/{t}" for t in _types_in(package, mode)))
    return 0


def _cmd_packages(mode: str, argv: list[str]) -> int:
    parser = argparse.ArgumentParser(prog=f"ros{mode} packages", usage=f"ros{mode} packages")
    parser.add_argument(
        "-s", dest="single_line", action="store_true", help="list all packages on a single line"
    )
    options = parser.parse_args(argv)
    joiner = " " if options.single_line else "\n"
    print(joiner.join(p.name for p in _packages_with(mode)))
    return 0


def _cmd_list(mode: str, argv: list[str]) -> int:
    parser = argparse.ArgumentParser(prog=f"ros{mode} list", usage=f"ros{mode} list")
    parser.parse_args(argv)
    for package in _packages_with(mode):
        for t in _types_in(package, mode):
            print(f"{package.name}/{t}")
    return 0


def run(mode: str, argv: list[str] | None = None) -> int:
    """Dispatch ``ros<mode> <command> ...`` (mode is ``msg`` or ``srv``)."""
    args = list(sys.argv[1:] if argv is None else argv)
    if not args or args[0] in ("--help", "-h"):
        print(usage(mode))
        return 0
    command, rest = args[0], args[1:]
    if command in ("show", "info"):
        return _cmd_show(mode, rest, command)
    if command == "md5":
        return _cmd_md5(mode, rest)
    if command == "package":
        return _cmd_package(mode, rest)
    if command == "packages":
        return _cmd_packages(mode, rest)
    if command == "list":
        return _cmd_list(mode, rest)
    print(usage(mode))
    return 64


def main(argv: list[str] | None = None) -> int:
    """``rosmsg``."""
    return run("msg", argv)


def main_srv(argv: list[str] | None = None) -> int:
    """``rossrv``."""
    return run("srv", argv)


console_main_msg = entry(main)
console_main_srv = entry(main_srv)
console_main = console_main_msg

if __name__ == "__main__":
    console_main_msg()

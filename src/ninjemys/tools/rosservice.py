"""``rosservice``: list, call, info, type, find, uri, args and node, with ROS 1's output.

Service types are learned the way ROS 1 learns them: a TCPROS probe (``probe=1``, md5 ``*``) to the
provider, which answers with its header and closes.
"""

from __future__ import annotations

import argparse
import sys
from typing import Any

from ninjemys import names
from ninjemys.errors import MasterError, NinjemysError, ServiceError, TypeNotFoundError
from ninjemys.master.graph import GraphSnapshot
from ninjemys.tools.cli import Subcommands, entry, master, run_subcommand

NAME = "rosservice"
ID = "/rosservice"
USAGE = """Commands:
\trosservice args\tprint service arguments
\trosservice call\tcall the service with the provided args
\trosservice find\tfind services by service type
\trosservice info\tprint information about service
\trosservice list\tlist active services
\trosservice type\tprint service type
\trosservice uri\tprint service ROSRPC uri

Type rosservice <command> -h for more detailed usage, e.g. 'rosservice call -h'
"""


class ServiceToolError(NinjemysError):
    """A rosservice usage or lookup error."""


def _resolve(name: str) -> str:
    return names.resolve_name(name, names.get_ros_namespace() + NAME)


def service_uri(client: Any, service: str) -> str | None:
    try:
        return client.lookup_service(service)
    except MasterError as exc:
        if exc.__class__.__name__ == "MasterUnreachable":
            raise
        return None


def probe(service: str, uri: str, timeout: float = 5.0) -> dict[str, str]:
    """The provider's connection header (:func:`ninjemys.node.services.probe`), as a rosservice error."""
    from ninjemys.node.services import probe as probe_service  # the node runtime only when probing

    try:
        return probe_service(service, uri, timeout, caller_id=ID)
    except ServiceError as exc:
        raise ServiceToolError(str(exc)) from None


def service_type(client: Any, service: str) -> str | None:
    uri = service_uri(client, service)
    if uri is None:
        return None
    return probe(service, uri).get("type")


def printable_args(msg: Any, prefix: str = "") -> str:
    """Request field names as ``rosservice args`` prints them (nested messages flattened)."""
    from ninjemys.idl.message import Message

    parts = []
    for name in msg.__slots__:
        value = getattr(msg, name)
        if isinstance(value, Message):
            parts.append(printable_args(value, prefix + name + "."))
        else:
            parts.append(prefix + name)
    return " ".join(p for p in parts if p)


def _service_class(type_name: str) -> Any:
    from ninjemys.idl.loader import get_service_class

    try:
        return get_service_class(type_name)
    except TypeNotFoundError:
        raise ServiceToolError(
            f"Unable to load type [{type_name}].\nHave you typed 'make' in [{type_name.split('/')[0]}]?"
        ) from None


def _cmd_list(args: argparse.Namespace) -> int:
    state = GraphSnapshot.fetch(master(ID), with_types=False)
    items = sorted(state.services.items())
    if args.namespace:
        ns = names.make_global_ns(_resolve(args.namespace))
        items = [(s, n) for s, n in items if s.startswith(ns)]
    for service, providers in items:
        print(f"{service} {','.join(providers)}" if args.print_nodes else service)
    return 0


def _cmd_info(args: argparse.Namespace) -> int:
    client = master(ID)
    service = _resolve(args.service)
    providers = GraphSnapshot.fetch(client, with_types=False).services.get(service)
    if not providers:
        print("ERROR: unknown service", file=sys.stderr)
        return 1
    print(f"Node: {providers[0]}")
    uri = service_uri(client, service)
    if uri is None:
        print("ERROR: service is no longer available", file=sys.stderr)
        return 1
    print(f"URI: {uri}")
    ttype = probe(service, uri).get("type")
    if ttype is None:
        print("ERROR: service is no longer available", file=sys.stderr)
        return 1
    print(f"Type: {ttype}")
    print(f"Args: {printable_args(_service_class(ttype)._request_class())}")
    return 0


def _cmd_type(args: argparse.Namespace) -> int:
    service = _resolve(args.service)
    ttype = service_type(master(ID), service)
    if ttype is None:
        print(f"Unknown service [{service}]", file=sys.stderr)
        return 1
    print(ttype)
    return 0


def _cmd_uri(args: argparse.Namespace) -> int:
    service = _resolve(args.service)
    uri = service_uri(master(ID), service)
    if uri is None:
        print(f"Unknown service: {service}", file=sys.stderr)
        return 1
    print(uri)
    return 0


def _cmd_node(args: argparse.Namespace) -> int:
    service = _resolve(args.service)
    providers = GraphSnapshot.fetch(master(ID), with_types=False).services.get(service)
    if not providers:
        print(f"Unknown service: {service}", file=sys.stderr)
        return 1
    print(providers[0])
    return 0


def _cmd_args(args: argparse.Namespace) -> int:
    service = _resolve(args.service)
    ttype = service_type(master(ID), service)
    if ttype is None:
        raise ServiceToolError(f"Unknown service [{service}]")
    print(printable_args(_service_class(ttype)._request_class()))
    return 0


def _cmd_find(args: argparse.Namespace) -> int:
    client = master(ID)
    found = []
    for service in GraphSnapshot.fetch(client, with_types=False).services:
        try:
            if service_type(client, service) == args.type:
                found.append(service)
        except ServiceToolError:
            continue
    print("\n".join(found))
    return 0


def _cmd_call(args: argparse.Namespace) -> int:
    from ninjemys.node import Node
    from ninjemys.rostime import Time
    from ninjemys.tools.msgargs import fill_message_args, parse_yaml_args, substitution_keys

    client = master(ID)
    service = _resolve(args.service)
    values = parse_yaml_args([a if a != "" else "''" for a in args.args])
    node = Node("rosservice", anonymous=True)
    try:
        if args.wait:
            client.get_pid()
            proxy = node.service_proxy(service, _probe_class(client, service, wait=True, node=node))
        else:
            proxy = node.service_proxy(service, _probe_class(client, service))
        request = proxy.request_class()
        fill_message_args(request, values, substitution_keys(Time.now()))
        try:
            response = proxy.call(request)
        except ServiceError as exc:
            raise ServiceToolError(str(exc)) from None
        if args.verbose:
            print(str(request))
            print("---")
        print(str(response))
    finally:
        node.shutdown("rosservice call done")
    return 0


def _probe_class(client: Any, service: str, wait: bool = False, node: Any = None) -> Any:
    while True:
        uri = service_uri(client, service)
        if uri is not None:
            try:
                ttype = probe(service, uri).get("type")
            except ServiceToolError:
                ttype = None
            if ttype:
                return _service_class(ttype)
        if not wait:
            raise ServiceToolError(f"Service [{service}] is not available.")
        node.wait_for_shutdown(0.1)
        if node.is_shutdown:
            raise ServiceToolError(f"gave up waiting for service [{service}]")


def _parser(command: str) -> argparse.ArgumentParser | None:
    sub = Subcommands(NAME, command)
    p = sub.add("list")
    p.add_argument("namespace", nargs="?")
    p.add_argument(
        "-n", "--nodes", dest="print_nodes", action="store_true", help="print nodes that provide service(s)"
    )
    p.set_defaults(run=_cmd_list)
    for cmd, run in (
        ("info", _cmd_info),
        ("type", _cmd_type),
        ("uri", _cmd_uri),
        ("node", _cmd_node),
        ("args", _cmd_args),
    ):
        p = sub.add(cmd)
        p.add_argument("service")
        p.set_defaults(run=run)
    p = sub.add("find")
    p.add_argument("type")
    p.set_defaults(run=_cmd_find)
    p = sub.add("call")
    p.add_argument("service")
    p.add_argument("args", nargs=argparse.REMAINDER)
    p.add_argument("-v", dest="verbose", action="store_true", help="print verbose output")
    p.add_argument("--wait", action="store_true", help="wait for service to be advertised")
    p.set_defaults(run=_cmd_call)
    return sub.parser if sub.matched else None


def _split_call_options(argv: list[str]) -> list[str]:
    """``rosservice call``: options come before the service name only; everything after it is YAML."""
    if argv[0] != "call":
        return argv
    opts = [a for a in argv[1:] if a in ("-v", "--wait")]
    rest = [a for a in argv[1:] if a not in ("-v", "--wait")]
    return ["call", *opts, *rest[:1], *(["--"] if len(rest) > 1 else []), *rest[1:]]


def main(argv: list[str] | None = None) -> int:
    return run_subcommand(sys.argv[1:] if argv is None else argv, USAGE, _parser, _split_call_options)


console_main = entry(main)

"""``rosnode``: list, info, ping, kill, machine and cleanup, printing exactly what ROS 1's prints."""

from __future__ import annotations

import argparse
import socket
import sys
from urllib.parse import urlparse

from ninjemys import names
from ninjemys.errors import MasterError, NinjemysError
from ninjemys.master.client import MasterClient
from ninjemys.master.graph import CONNECTION_INFO, GraphSnapshot, bus_info, node_api, ping, ping_node, slave
from ninjemys.tools.cli import Subcommands, entry, error, master, run_subcommand

NAME = "rosnode"
ID = "/rosnode"
USAGE = """rosnode is a command-line tool for printing information about ROS Nodes.

Commands:
\trosnode ping\ttest connectivity to node
\trosnode list\tlist active nodes
\trosnode info\tprint information about node
\trosnode machine\tlist nodes running on a particular machine or list machines
\trosnode kill\tkill a running node
\trosnode cleanup\tpurge registration information of unreachable nodes

Type rosnode <command> -h for more detailed usage, e.g. 'rosnode ping -h'
"""


class NodeToolError(NinjemysError):
    """A rosnode usage or lookup error."""


def _resolve(name: str) -> str:
    return names.resolve_name(name, names.get_ros_namespace() + NAME)


def _cmd_list(args: argparse.Namespace) -> int:
    client = master(ID)
    nodes = GraphSnapshot.fetch(client, with_types=False).node_names()
    if args.namespace:
        ns = names.make_global_ns(_resolve(args.namespace))
        nodes = [n for n in nodes if n.startswith(ns) or n == ns.rstrip("/")]
    if args.list_all:
        lines = [f"{node_api(client, n) or 'unknown address'} \t{n}" for n in nodes]
    elif args.list_uri:
        lines = [node_api(client, n) or "unknown address" for n in nodes]
    else:
        lines = nodes
    print("\n".join(lines))
    return 0


def _topic_type(topic: str, state: GraphSnapshot) -> str:
    return state.published_types.get(topic, "unknown type")


def info_text(node: str, state: GraphSnapshot) -> str:
    """The first block of ``rosnode info``: publications, subscriptions, services."""
    pubs, subs, srvs = state.topics_of(node)
    buff = f"Node [{node}]"
    for title, items in (("Publications", pubs), ("Subscriptions", subs)):
        if items:
            buff += f"\n{title}: \n" + "\n".join(f" * {t} [{_topic_type(t, state)}]" for t in items) + "\n"
        else:
            buff += f"\n{title}: None\n"
    if srvs:
        buff += "\nServices: \n" + "\n".join(f" * {s}" for s in srvs) + "\n"
    else:
        buff += "\nServices: None\n"
    return buff


def connections_text(uri: str, state: GraphSnapshot, client: object) -> str:
    """The ``Pid:`` / ``Connections:`` block, from the node's getPid and getBusInfo."""
    pid, rows = bus_info(uri, ID)
    buff = f"Pid: {pid}\n"
    if not rows:
        return buff
    buff += "Connections:\n"
    api_cache: dict[str, str | None] = {}
    for row in rows:
        dest, direction, transport, topic = row[1], row[2], row[3], row[4]
        connected = row[5] if len(row) > 5 else True
        if not connected:
            continue
        buff += f" * topic: {topic}\n"
        buff += f"    * to: {_lookup_peer(client, state, topic, dest, api_cache)}\n"
        buff += "    * direction: " + {"i": "inbound", "o": "outbound"}.get(direction, "unknown")
        if len(row) > 6:
            match = CONNECTION_INFO.match(str(row[6]))
            if match is not None:
                buff += " (%s - %s) [%s]" % match.groups()
        buff += "\n"
        buff += f"    * transport: {transport}\n"
    return buff


def _lookup_peer(
    client: object, state: GraphSnapshot, topic: str, dest: str, cache: dict[str, str | None]
) -> str:
    """rosnode prints ``/node (uri)`` when the peer's URI belongs to a node on that topic."""
    for table in (state.publishers, state.subscribers):
        for node in table.get(topic, []):
            if node not in cache:
                cache[node] = node_api(client, node)  # type: ignore[arg-type]
            if cache[node] == dest:
                return f"{node} ({dest})"
    return str(dest)


def _cmd_info(args: argparse.Namespace) -> int:
    client = master(ID)
    for raw in args.nodes:
        node = _resolve(raw)
        state = GraphSnapshot.fetch(client)
        print("-" * 80)
        print(info_text(node, state))
        uri = node_api(client, node)
        if not uri:
            print(f"cannot contact [{node}]: unknown node", file=sys.stderr)
            continue
        if not args.quiet:
            print(f"\ncontacting node {uri} ...")
            try:
                print(connections_text(uri, state, client))
            except MasterError:
                error(f"Communication with node[{uri}] failed!")
                return 1
    return 0


def _ping_node(client: MasterClient, node: str, max_count: int | None, verbose: bool) -> bool:
    return ping_node(
        node,
        lambda name, _refresh: node_api(client, name),
        ID,
        max_count=max_count,
        verbose=verbose,
        err=lambda line: print(line, file=sys.stderr),
    )


def _cmd_ping(args: argparse.Namespace) -> int:
    client = master(ID)
    if args.ping_all:
        if args.node:
            raise NodeToolError(f"Invalid arguments '{args.node}' used with --all")
        if args.count:
            raise NodeToolError("-c may not be used with --all")
        nodes = GraphSnapshot.fetch(client, with_types=False).node_names()
        print("Will ping the following nodes: \n" + "".join(f" * {n}\n" for n in nodes))
        for node in nodes:
            _ping_node(client, node, 1, True)
        return 0
    if not args.node:
        raise NodeToolError("Please enter a node to ping")
    node = _resolve(args.node)
    print(f"rosnode: node is [{node}]")
    return 0 if _ping_node(client, node, args.count, True) else 1


def _cmd_kill(args: argparse.Namespace) -> int:
    client = master(ID)
    known = GraphSnapshot.fetch(client, with_types=False).node_names()
    if args.kill_all:
        if args.nodes:
            raise NodeToolError("invalid arguments with kill all (-a) option")
        targets = known
    elif not args.nodes:
        if not known:
            print("No nodes running", file=sys.stderr)
            return 0
        sys.stdout.write("\n".join(f"{i + 1}. {n}" for i, n in enumerate(known)))
        sys.stdout.write("\n\nPlease enter the number of the node you wish to kill.\n> ")
        sys.stdout.flush()
        targets = [known[_read_selection(len(known)) - 1]]
    else:
        targets = [_resolve(n) for n in args.nodes]
        unknown = [n for n in targets if n not in known]
        if unknown:
            raise NodeToolError("Unknown node(s):\n" + "\n".join(f" * {n}" for n in unknown))
    if len(targets) > 1:
        print("killing:\n" + "\n".join(f" * {n}" for n in targets))
    elif targets:
        print(f"killing {targets[0]}")
    failed = []
    for node in targets:
        uri = node_api(client, node)
        if not uri:
            failed.append(node)
            continue
        peer = slave(uri, ID, timeout=3.0)
        try:
            peer.call("shutdown", "user request")
        except MasterError:
            pass  # a node tearing down while answering counts as killed, as in ROS 1
        finally:
            peer.close()
    if failed:
        print("ERROR: Failed to kill:\n" + "\n".join(f" * {n}" for n in failed), file=sys.stderr)
        return 1
    print("killed")
    return 0


def _read_selection(count: int) -> int:
    while True:
        line = sys.stdin.readline()
        if not line:
            raise NodeToolError("no selection made")
        try:
            choice = int(line.strip())
        except ValueError:
            print("ERROR: please enter a number (ctrl-C to cancel)")
            continue
        if 1 <= choice <= count:
            return choice
        print("ERROR: invalid selection. Please enter a number (ctrl-C to cancel)")


def _hostname(uri: str | None) -> str | None:
    return urlparse(uri).hostname if uri else None


def _cmd_machine(args: argparse.Namespace) -> int:
    client = master(ID)
    nodes = GraphSnapshot.fetch(client, with_types=False).node_names()
    hosts = {n: _hostname(node_api(client, n)) for n in nodes}
    if args.machine is None:
        machines: list[str] = []
        for host in hosts.values():
            if host and host not in machines:
                machines.append(host)
        print("\n".join(sorted(machines)))
        return 0
    try:
        wanted = {info[4][0] for info in socket.getaddrinfo(args.machine, 0, 0, 0, socket.SOL_TCP)}
    except OSError:
        raise NodeToolError(f"cannot resolve machine name [{args.machine}] to address") from None
    matches = []
    for node, host in hosts.items():
        if host is None:
            continue
        if host == args.machine:
            matches.append(node)
            continue
        try:
            addrs = {info[4][0] for info in socket.getaddrinfo(host, 0, 0, 0, socket.SOL_TCP)}
        except OSError:
            continue
        if addrs & wanted:
            matches.append(node)
    print("\n".join(sorted(matches)))
    return 0


def _cmd_cleanup(args: argparse.Namespace) -> int:
    client = master(ID)
    state = GraphSnapshot.fetch(client, with_types=False)
    dead = []
    for node in state.node_names():
        uri = node_api(client, node)
        try:
            if uri is None:
                raise MasterError("unknown node")
            ping(uri, ID, timeout=3.0)
        except MasterError:
            dead.append((node, uri))
    if not dead:
        return 0
    print("Unable to contact the following nodes:")
    print("\n".join(f" * {n}" for n, _ in dead))
    print("Warning: these might include alive and functioning nodes, e.g. in unstable networks.")
    print("Cleanup will purge all information about these nodes from the master.")
    print("Please type y or n to continue:")
    answer = sys.stdin.readline().strip().lower()
    if answer != "y":
        print("aborting")
        return 0
    for node, uri in dead:
        print("Unregistering", node)
        if uri is None:
            continue
        purge = master(node)
        for topic, members in state.publishers.items():
            if node in members:
                purge.unregister_publisher(topic, uri)
        for topic, members in state.subscribers.items():
            if node in members:
                purge.unregister_subscriber(topic, uri)
        for service, members in state.services.items():
            if node in members:
                try:
                    purge.unregister_service(service, purge.lookup_service(service))
                except MasterError:
                    continue
    print("done")
    return 0


def _parser(command: str) -> argparse.ArgumentParser | None:
    sub = Subcommands(NAME, command)
    p = sub.add("list")
    p.add_argument("namespace", nargs="?")
    p.add_argument("-u", dest="list_uri", action="store_true", help="list XML-RPC URIs")
    p.add_argument("-a", "--all", dest="list_all", action="store_true", help="list all information")
    p.set_defaults(run=_cmd_list)
    p = sub.add("info")
    p.add_argument("nodes", nargs="+")
    p.add_argument("-q", "--quiet", action="store_true", help="do not contact the nodes")
    p.set_defaults(run=_cmd_info)
    p = sub.add("ping")
    p.add_argument("node", nargs="?")
    p.add_argument("-a", "--all", dest="ping_all", action="store_true", help="ping all nodes")
    p.add_argument("-c", dest="count", type=int, metavar="COUNT", help="number of pings to send")
    p.set_defaults(run=_cmd_ping)
    p = sub.add("kill")
    p.add_argument("nodes", nargs="*")
    p.add_argument("-a", "--all", dest="kill_all", action="store_true", help="kill all nodes")
    p.set_defaults(run=_cmd_kill)
    p = sub.add("machine")
    p.add_argument("machine", nargs="?")
    p.set_defaults(run=_cmd_machine)
    p = sub.add("cleanup")
    p.set_defaults(run=_cmd_cleanup)
    return sub.parser if sub.matched else None


def main(argv: list[str] | None = None) -> int:
    return run_subcommand(sys.argv[1:] if argv is None else argv, USAGE, _parser)


console_main = entry(main)

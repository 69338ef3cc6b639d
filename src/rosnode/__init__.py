"""rosnode's Python API as ROS 1 programs and test harnesses import it: node names, their URIs,
pinging and killing nodes, the info text ``rosnode info`` prints, master cleanup.

Nodes are called with the standard library's XML-RPC client, as ROS 1 does, so a dead node shows the
same socket errors; the master through the rosgraph facade. (The ``rosnode`` command is
ninjemys.tools.rosnode; the layering keeps facades below the tools.)
"""

from __future__ import annotations

import errno
import re
import socket
import sys
import time
from typing import Any
from urllib.parse import urlparse

import rosgraph
import rosgraph.names
import rostopic
from ninjemys.net.auth import server_proxy as ServerProxy  # noqa: N812 - signs when NINJEMYS_SECRET is set

__all__ = [
    "NAME",
    "ID",
    "ROSNodeException",
    "ROSNodeIOException",
    "get_api_uri",
    "lookup_uri",
    "get_node_names",
    "get_machines_by_nodes",
    "get_nodes_by_machine",
    "kill_nodes",
    "rosnode_listnodes",
    "rosnode_ping",
    "rosnode_ping_all",
    "cleanup_master_blacklist",
    "cleanup_master_whitelist",
    "rosnode_cleanup",
    "get_node_info_description",
    "get_node_connection_info_description",
    "rosnode_info",
    "rosnode_debugnode",
    "rosnodemain",
]

NAME = "rosnode"
ID = "/rosnode"
CONNECTION_PATTERN = re.compile(r"\w+ connection on port (\d+) to \[(.*) on socket (\d+)\]")
_IO_ERROR = "Unable to communicate with master!"


class ROSNodeException(Exception):
    """A rosnode operation failed."""


class ROSNodeIOException(ROSNodeException):
    """The master or a node could not be reached."""


def _succeed(args: Any) -> Any:
    code, msg, val = args
    if code != 1:
        raise ROSNodeException(f"remote call failed: {msg}")
    return val


_caller_apis: dict[str, str] = {}


def get_api_uri(master: rosgraph.Master, caller_id: str, skip_cache: bool = False) -> str | None:
    """The XML-RPC URI of node ``caller_id`` (cached unless ``skip_cache``), None if unknown."""
    api = _caller_apis.get(caller_id)
    if not api or skip_cache:
        try:
            api = master.lookupNode(caller_id)
        except rosgraph.MasterError:
            return None
        except OSError:
            raise ROSNodeIOException(_IO_ERROR) from None
        _caller_apis[caller_id] = api
    return api


def lookup_uri(master: rosgraph.Master, system_state: Any, topic: str, uri: str) -> str:
    """``node (uri)`` for the node of ``topic`` at ``uri``, else ``uri``."""
    for entries in system_state[0:2]:
        for name, nodes in entries:
            if name == topic:
                for n in nodes:
                    if rostopic.get_api(master, n) == uri:
                        return f"{n} ({uri})"
    return uri


def _state(master: rosgraph.Master) -> Any:
    try:
        return master.getSystemState()
    except OSError:
        raise ROSNodeIOException(_IO_ERROR) from None


def get_node_names(namespace: str | None = None) -> list[str]:
    """Every node with a registration, or those in ``namespace`` (already resolved)."""
    state = _state(rosgraph.Master(ID))
    prefix = rosgraph.names.make_global_ns(namespace) if namespace else None
    nodes = {
        n
        for part in state
        for _name, registered in part
        for n in registered
        if prefix is None or n.startswith(prefix) or n == namespace
    }
    return list(nodes)


def _host(uri: str) -> str | None:
    return urlparse(uri).hostname


def get_machines_by_nodes() -> list[str]:
    """The hosts the nodes run on (one master lookup per node)."""
    master = rosgraph.Master(ID)
    machines: list[str] = []
    for n in get_node_names():
        try:
            h = _host(master.lookupNode(n))
        except rosgraph.MasterError:
            continue
        except OSError:
            raise ROSNodeIOException(_IO_ERROR) from None
        if h not in machines and h is not None:
            machines.append(h)
    return machines


def _addresses(host: str) -> list[str]:
    return [str(a[4][0]) for a in socket.getaddrinfo(host, 0, 0, 0, socket.SOL_TCP)]


def get_nodes_by_machine(machine: str) -> list[str]:
    """The nodes whose URI's host is ``machine`` or resolves to one of its addresses."""
    master = rosgraph.Master(ID)
    try:
        actual = _addresses(machine)
    except OSError:
        raise ROSNodeException(f"cannot resolve machine name [{machine}] to address") from None
    found = []
    for n in get_node_names():
        try:
            h = _host(master.lookupNode(n))
        except rosgraph.MasterError:
            continue
        except OSError:
            raise ROSNodeIOException(_IO_ERROR) from None
        if h == machine or h in actual or (h and set(_addresses(h)) & set(actual)):
            found.append(n)
    return found


def kill_nodes(node_names: list[str]) -> tuple[list[str], list[str]]:
    """Ask each node to shut down; ``(asked, unknown to the master)``. A node that does not answer
    still counts as asked, as in ROS 1 (it may have died on the way)."""
    master = rosgraph.Master(ID)
    success: list[str] = []
    fail: list[str] = []
    tocall = []
    for n in node_names:
        try:
            tocall.append((n, master.lookupNode(n)))
        except Exception:  # noqa: BLE001  (ROS 1: any lookup failure is a failure for that node)
            fail.append(n)
    for n, uri in tocall:
        try:
            _succeed(ServerProxy(uri).shutdown(ID, "user request"))
        except Exception:  # noqa: BLE001, S110  (the node may exit before answering)
            pass
        success.append(n)
    return success, fail


def _sub_rosnode_listnodes(
    namespace: str | None = None, list_uri: bool = False, list_all: bool = False
) -> str:
    master = rosgraph.Master(ID)
    nodes = sorted(get_node_names(namespace))
    if list_all:
        return "\n".join(f"{get_api_uri(master, n) or 'unknown address'} \t{n}" for n in nodes)
    if list_uri:
        return "\n".join(get_api_uri(master, n) or "unknown address" for n in nodes)
    return "\n".join(nodes)


def rosnode_listnodes(namespace: str | None = None, list_uri: bool = False, list_all: bool = False) -> None:
    """Print the nodes (or their URIs, or both) as ``rosnode list`` does."""
    print(_sub_rosnode_listnodes(namespace=namespace, list_uri=list_uri, list_all=list_all))


def rosnode_ping(
    node_name: str, max_count: int | None = None, verbose: bool = False, skip_cache: bool = False
) -> bool:
    """Call the node's getPid ``max_count`` times (forever if None), a second apart; True if it
    answered. Failures print ROS 1's messages on stderr and return False."""
    master = rosgraph.Master(ID)
    node_api = get_api_uri(master, node_name, skip_cache=skip_cache)
    if not node_api:
        print(f"cannot ping [{node_name}]: unknown node", file=sys.stderr)
        return False
    timeout = 3.0
    if verbose:
        print(f"pinging {node_name} with a timeout of {timeout}s")
    socket.setdefaulttimeout(timeout)
    node = ServerProxy(node_api)
    count = 0
    acc = 0.0
    try:
        while True:
            try:
                start = time.time()
                _succeed(node.getPid(ID))
                dur = (time.time() - start) * 1000.0
                acc += dur
                count += 1
                if verbose:
                    print(f"xmlrpc reply from {node_api}\ttime={dur:f}ms")
            except TimeoutError:
                print(f"connection to [{node_name}] timed out", file=sys.stderr)
                return False
            except OSError as e:
                if e.errno == -2 or (isinstance(e, socket.gaierror) and e.errno == socket.EAI_NONAME):
                    print(f"ERROR: Unknown host [{_host(node_api)}] for node [{node_name}]", file=sys.stderr)
                elif e.errno == errno.ECONNREFUSED:
                    new_api = get_api_uri(master, node_name, skip_cache=True)
                    if not new_api:
                        print(f"cannot ping [{node_name}]: unknown node", file=sys.stderr)
                        return False
                    if new_api != node_api:
                        if verbose:
                            print(f"node url has changed from [{node_api}] to [{new_api}], retrying to ping")
                        node_api = new_api
                        node = ServerProxy(node_api)
                        continue
                    print(f"ERROR: connection refused to [{node_api}]", file=sys.stderr)
                else:
                    print(f"connection to [{node_name}] failed", file=sys.stderr)
                return False
            if max_count and count >= max_count:
                break
            time.sleep(1.0)
    except KeyboardInterrupt:
        pass
    if verbose and count > 1:
        print(f"ping average: {acc / count:f}ms")
    return True


def rosnode_ping_all(verbose: bool = False, skip_cache: bool = False) -> tuple[list[str], list[str]]:
    """Ping every registered node once: ``(answered, silent)``."""
    nodes = list(
        {n for part in _state(rosgraph.Master(ID)) for _name, registered in part for n in registered}
    )
    if verbose:
        print("Will ping the following nodes: \n" + "".join(f" * {n}\n" for n in nodes))
    pinged: list[str] = []
    unpinged: list[str] = []
    for node in nodes:
        (
            pinged if rosnode_ping(node, max_count=1, verbose=verbose, skip_cache=skip_cache) else unpinged
        ).append(node)
    return pinged, unpinged


def _unregister(master: rosgraph.Master, state: Any, keep: Any) -> None:
    """Unregister, as each node itself, every registration of a node for which ``keep`` is False."""
    pubs, subs, srvs = state
    for topic, nodes in pubs:
        for n in nodes:
            if not keep(n) and (api := get_api_uri(master, n)):
                rosgraph.Master(n).unregisterPublisher(topic, api)
    for topic, nodes in subs:
        for n in nodes:
            if not keep(n) and (api := get_api_uri(master, n)):
                rosgraph.Master(n).unregisterSubscriber(topic, api)
    for service, nodes in srvs:
        for n in nodes:
            if not keep(n):
                rosgraph.Master(n).unregisterService(service, master.lookupService(service))


def cleanup_master_blacklist(master: rosgraph.Master, blacklist: list[str]) -> None:
    """Remove every registration of the nodes in ``blacklist`` from the master (and our URI cache)."""
    state = master.getSystemState()
    for n in blacklist:
        print("Unregistering", n)
    _unregister(master, state, lambda n: n not in blacklist)
    for n in blacklist:
        _caller_apis.pop(n, None)


def cleanup_master_whitelist(master: rosgraph.Master, whitelist: list[str]) -> None:
    """Remove every registration of the nodes not in ``whitelist`` from the master."""
    _unregister(master, master.getSystemState(), lambda n: n in whitelist)


def rosnode_cleanup() -> None:
    """Ping every node and, after the user types ``y``, purge the silent ones from the master."""
    _pinged, unpinged = rosnode_ping_all()
    if not unpinged:
        return
    master = rosgraph.Master(ID)
    print("Unable to contact the following nodes:")
    print("\n".join(f" * {n}" for n in unpinged))
    print("Warning: these might include alive and functioning nodes, e.g. in unstable networks.")
    print("Cleanup will purge all information about these nodes from the master.")
    print("Please type y or n to continue:")
    answer = sys.stdin.readline()
    while answer.strip() not in ("y", "n"):
        answer = sys.stdin.readline()
    if answer.strip() == "n":
        print("aborting")
        return
    cleanup_master_blacklist(master, unpinged)
    print("done")


def get_node_info_description(node_name: str) -> str:
    """The first part of ``rosnode info``: the node's publications, subscriptions and services."""
    master = rosgraph.Master(ID)
    try:
        state = master.getSystemState()
        types = dict((t, tt) for t, tt in master.getPublishedTopics("/"))
    except OSError:
        raise ROSNodeIOException(_IO_ERROR) from None
    pubs, subs, srvs = (sorted(t for t, nodes in part if node_name in nodes) for part in state)
    buff = f"Node [{node_name}]"
    for title, names in (("Publications", pubs), ("Subscriptions", subs)):
        if names:
            buff += (
                f"\n{title}: \n" + "\n".join(f" * {t} [{types.get(t, 'unknown type')}]" for t in names) + "\n"
            )
        else:
            buff += f"\n{title}: None\n"
    if srvs:
        buff += "\nServices: \n" + "\n".join(f" * {s}" for s in srvs) + "\n"
    else:
        buff += "\nServices: None\n"
    return buff


def get_node_connection_info_description(node_api: str, master: rosgraph.Master) -> str:
    """The second part of ``rosnode info``: the node's pid and its connections (getBusInfo)."""
    socket.setdefaulttimeout(5.0)
    node = ServerProxy(node_api)
    state = master.getSystemState()
    try:
        buff = f"Pid: {_succeed(node.getPid(ID))}\n"
        businfo = _succeed(node.getBusInfo(ID))
        if businfo:
            buff += "Connections:\n"
        for info in businfo:
            dest_id, direction, transport, topic = info[1:5]
            if len(info) > 5 and not info[5]:
                continue
            buff += f" * topic: {topic}\n"
            buff += f"    * to: {lookup_uri(master, state, topic, dest_id)}\n"
            buff += "    * direction: " + {"i": "inbound", "o": "outbound"}.get(direction, "unknown")
            if len(info) > 6:
                match = CONNECTION_PATTERN.match(info[6])
                if match is not None:
                    buff += " ({} - {}) [{}]".format(*match.groups())
            buff += f"\n    * transport: {transport}\n"
    except OSError:
        raise ROSNodeIOException(f"Communication with node[{node_api}] failed!") from None
    return buff


def rosnode_info(node_name: str, quiet: bool = False) -> None:
    """Print what ``rosnode info NODE`` prints (with ``quiet``, without contacting the node)."""
    master = rosgraph.Master(ID)
    node_name = rosgraph.names.script_resolve_name("rosnode", node_name)
    print("-" * 80)
    print(get_node_info_description(node_name))
    node_api = get_api_uri(master, node_name)
    if not node_api:
        print(f"cannot contact [{node_name}]: unknown node", file=sys.stderr)
        return
    if not quiet:
        print(f"\ncontacting node {node_api} ...")
        print(get_node_connection_info_description(node_api, master))


rosnode_debugnode = rosnode_info


def rosnodemain(argv: list[str] | None = None) -> None:
    """The ``rosnode`` command with ``argv`` (``argv[0]`` is the program name), as ROS 1's entry point:
    our ``rosnode`` runs it; a failure exits with its status."""
    import subprocess

    from ninjemys.commands import command_path

    argv = sys.argv if argv is None else argv
    code = subprocess.call([command_path("rosnode"), *argv[1:]])
    if code:
        sys.exit(code)

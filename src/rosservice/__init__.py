"""rosservice's Python API as ROS 1 programs and test harnesses import it: the service list, a
service's type (probed from its TCPROS header, as the master does not know it), URI, node and class,
and ``call_service`` with YAML-parsed arguments.

It sits on the rosgraph, rospy and genpy facades; the ``rosservice`` command is
ninjemys.tools.rosservice (the layering keeps facades below the tools).
"""

from __future__ import annotations

import sys
from typing import Any

import genpy
import genpy.message
import rosgraph
import rosgraph.names
import rosmsg
import rospy
from ninjemys.errors import ServiceError
from ninjemys.master.snapshot import GraphSnapshot
from ninjemys.node.services import probe
from roslib.message import get_service_class

__all__ = [
    "NAME",
    "ROSServiceException",
    "ROSServiceIOException",
    "get_service_headers",
    "get_service_type",
    "get_service_uri",
    "get_service_node",
    "get_service_list",
    "rosservice_find",
    "get_service_class_by_name",
    "call_service",
    "has_service_args",
    "get_service_args",
    "rosservicemain",
]

NAME = "rosservice"
_IO_ERROR = "Unable to communicate with master!"


class ROSServiceException(Exception):
    """A rosservice operation failed."""


class ROSServiceIOException(ROSServiceException):
    """The master or a service could not be reached."""


def _get_master() -> rosgraph.Master:
    return rosgraph.Master("/rosservice")


def _succeed(args: Any) -> Any:
    code, msg, val = args
    if code != 1:
        raise ROSServiceException(f"remote call failed: {msg}")
    return val


def _graph() -> GraphSnapshot:
    """The registrations now, indexed as every graph reader indexes them (ninjemys.master.snapshot)."""
    try:
        return GraphSnapshot.from_system_state(_get_master().getSystemState())
    except OSError:
        raise ROSServiceIOException(_IO_ERROR) from None


def _parse_rosrpc_uri(uri: str) -> tuple[str, int]:
    if not uri.startswith("rosrpc://"):
        raise ValueError(uri)
    host, _, port = uri[len("rosrpc://") :].rstrip("/").rpartition(":")
    if not host:
        raise ValueError(uri)
    return host, int(port)


def get_service_headers(service_name: str, service_uri: str) -> dict[str, str]:
    """The TCPROS header service ``service_name`` answers a probe with (its type, md5sum ...): the
    probe is :func:`ninjemys.node.services.probe` (the rosservice command's, the gateway's), with
    ROS 1's exceptions."""
    try:
        _parse_rosrpc_uri(service_uri)
    except ValueError:
        raise ROSServiceException(
            f"service [{service_name}] has an invalid RPC URI [{service_uri}]"
        ) from None
    try:
        return probe(service_name, service_uri, 5.0, caller_id="/rosservice")
    except ServiceError:
        raise ROSServiceIOException(
            f"Unable to communicate with service [{service_name}], address [{service_uri}]"
        ) from None


def get_service_type(service_name: str) -> str | None:
    """The type of ``service_name`` (probed), or None if no node provides it."""
    try:
        uri = _get_master().lookupService(service_name)
    except rosgraph.MasterError:
        return None
    except OSError:
        raise ROSServiceIOException(_IO_ERROR) from None
    return get_service_headers(service_name, uri).get("type")


def get_service_uri(service_name: str) -> str | None:
    """The rosrpc:// URI of ``service_name``, or None."""
    try:
        return _get_master().lookupService(service_name)
    except rosgraph.MasterException:
        return None
    except OSError:
        raise ROSServiceIOException(_IO_ERROR) from None


def get_service_list(
    node: str | None = None, namespace: str | None = None, include_nodes: bool = False
) -> list[Any]:
    """The service names (of ``node``, under ``namespace``), or ``[name, [node, ...]]`` pairs."""
    srvs = [[name, list(nodes)] for name, nodes in _graph().services.items()]
    if namespace:
        g_ns = rosgraph.names.make_global_ns(namespace)
        srvs = [x for x in srvs if x[0] == namespace or x[0].startswith(g_ns)]
    if node is not None:
        srvs = [x for x in srvs if node in x[1]]
    if include_nodes:
        return srvs if node is None else [(s, nodes) for s, nodes in srvs]
    return [s for s, _nodes in srvs]


def get_service_node(service_name: str) -> str | None:
    """The node providing ``service_name``, or None."""
    for name, nodes in get_service_list(include_nodes=True):
        if name == service_name and nodes:
            return nodes[0]
    return None


def rosservice_find(service_type: str) -> list[str]:
    """The services of type ``service_type`` (each probed; unreachable ones are skipped)."""
    found = []
    for s in _graph().services:
        try:
            if get_service_type(s) == service_type:
                found.append(s)
        except ROSServiceIOException:
            continue
    return found


def get_service_class_by_name(service_name: str) -> Any:
    """The service class of ``service_name`` (probes the service)."""
    service_type = get_service_type(service_name)
    if not service_type:
        if service_name not in get_service_list():
            raise ROSServiceException(f"Service [{service_name}] is not available.")
        raise ROSServiceException(f"Unable to determine type of service [{service_name}].")
    cls = get_service_class(service_type)
    if cls and service_type.endswith("Request") and not hasattr(cls, "_request_class"):
        service_type = service_type[:-7]
        cls = get_service_class(service_type)
    if cls is None:
        pkg = service_type.split("/")[0] if "/" in service_type else None
        raise ROSServiceException(f"Unable to load type [{service_type}].\nHave you typed 'make' in [{pkg}]?")
    return cls


def _argsummary(args: Any) -> str:
    if type(args) in (tuple, list):
        return "\n".join(f" * {a} (type {type(a).__name__})" for a in args)
    return f" * {args} (type {type(args).__name__})"


def call_service(service_name: str, service_args: list[Any], service_class: Any = None) -> tuple[Any, Any]:
    """Call ``service_name`` with YAML-parsed ``service_args`` (``now`` and ``auto`` as keys);
    returns ``(request, response)``. Starts an anonymous ``rosservice`` node if none runs, as ROS 1."""
    from std_msgs.msg import Header

    rospy.init_node("rosservice", anonymous=True)
    if service_class is None:
        service_class = get_service_class_by_name(service_name)
    request = service_class._request_class()
    try:
        now = rospy.get_rostime()
        genpy.message.fill_message_args(request, service_args, keys={"now": now, "auto": Header(stamp=now)})
    except genpy.MessageException as e:
        raise ROSServiceException(
            f"Incompatible arguments to call service:\n{e}\nProvided arguments are:\n{_argsummary(service_args)}"
            f"\n\nService arguments are: [{genpy.message.get_printable_message_args(request)}]"
        ) from None
    try:
        return request, rospy.ServiceProxy(service_name, service_class)(request)
    except rospy.ServiceException as e:
        raise ROSServiceException(str(e)) from None
    except (genpy.SerializationError, rospy.ROSSerializationException) as e:
        raise ROSServiceException(
            "Unable to send request. One of the fields has an incorrect type:\n"
            f"  {e}\n\nsrv file:\n{rosmsg.get_srv_text(service_class._type)}"
        ) from None


def has_service_args(service_name: str, service_class: Any = None) -> bool:
    """True if the service's request has fields."""
    service_name = rosgraph.names.script_resolve_name("rosservice", service_name)
    if service_class is None:
        service_class = get_service_class_by_name(service_name)
    return len(service_class._request_class.__slots__) > 0


def get_service_args(service_name: str) -> str:
    """The request's field names as ``rosservice args`` prints them."""
    service_name = rosgraph.names.script_resolve_name("rosservice", service_name)
    return genpy.message.get_printable_message_args(get_service_class_by_name(service_name)._request_class)


def rosservicemain(argv: list[str] = sys.argv) -> None:
    """The ``rosservice`` command with ``argv`` (``argv[0]`` is the program name), as ROS 1's entry point:
    our ``rosservice`` runs it; a failure exits with its status."""
    import subprocess

    from ninjemys.commands import command_path

    code = subprocess.call([command_path("rosservice"), *argv[1:]])
    if code:
        sys.exit(code)

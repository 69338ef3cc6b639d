"""The ``rosapi`` node: graph, type and parameter introspection as services, for rosbridge clients.

Names, request and response types are ROS 1 rosapi's (``/rosapi/topics``, ``/rosapi/get_param``,
...; the ``rosapi`` interface package ships with ninjemys). Parameters travel as JSON text both
ways, as rosapi does: ``get_param`` answers ``json.dumps(value)`` and ``set_param`` parses its
value as JSON, keeping it as a string when it is not JSON.

``rosrun rosapi rosapi_node`` (and ``rosbridge_websocket.launch``) run it as its own node.
"""

from __future__ import annotations

import json
import logging
import sys
from typing import Any

from ninjemys.errors import NinjemysError
from ninjemys.idl.loader import get_message_class, get_message_spec, get_service_class
from ninjemys.net.addresses import split_uri
from ninjemys.node import Node
from ninjemys.node.clock import for_node
from ninjemys.node.services import probe
from ninjemys.rostime import Time

log = logging.getLogger(__name__)

_PRIMITIVES = {
    "bool",
    "byte",
    "char",
    "int8",
    "uint8",
    "int16",
    "uint16",
    "int32",
    "uint32",
    "int64",
    "uint64",
    "float32",
    "float64",
    "string",
}
_TIMES = ("time", "duration")


def typedefs(type_name: str) -> list[dict[str, Any]]:
    """rosapi's ``TypeDef`` list for ``type_name``: the type first, then every type nested in it."""
    out: list[dict[str, Any]] = []
    seen: set[str] = set()

    def visit(name: str) -> None:
        if name in seen:
            return
        seen.add(name)
        if name in _TIMES:
            out.append(
                {
                    "type": name,
                    "fieldnames": ["secs", "nsecs"],
                    "fieldtypes": ["int32", "int32"],
                    "fieldarraylen": [-1, -1],
                    "examples": ["0", "0"],
                    "constnames": [],
                    "constvalues": [],
                }
            )
            return
        spec = get_message_spec(name)
        cls = get_message_class(name)
        default = cls()
        entry: dict[str, Any] = {
            "type": name,
            "fieldnames": [],
            "fieldtypes": [],
            "fieldarraylen": [],
            "examples": [],
            "constnames": [c.name for c in spec.constants],
            "constvalues": [c.value_text for c in spec.constants],
        }
        nested = []
        for field in spec.fields:
            ftype = field.type
            entry["fieldnames"].append(field.name)
            entry["fieldtypes"].append(ftype.base)
            if ftype.is_array:
                entry["fieldarraylen"].append(ftype.array_len or 0)
                entry["examples"].append("[]")
            else:
                entry["fieldarraylen"].append(-1)
                if ftype.base in _PRIMITIVES:
                    entry["examples"].append(str(getattr(default, field.name)))
                else:
                    entry["examples"].append("{}")
            if ftype.base not in _PRIMITIVES:
                nested.append(ftype.base)
        out.append(entry)
        for sub in nested:
            visit(sub)

    visit(type_name)
    return out


class RosApi:
    """The rosapi services on ``node`` (a node named ``rosapi`` gives ``/rosapi/*``)."""

    def __init__(self, node: Node) -> None:
        self.node = node
        self.master = node.master
        self.clock = for_node(node)
        self._servers = []
        for name, srv, handler in (
            ("topics", "Topics", self.topics),
            ("topics_for_type", "TopicsForType", self.topics_for_type),
            ("topics_and_raw_types", "TopicsAndRawTypes", self.topics_and_raw_types),
            ("services", "Services", self.services),
            ("services_for_type", "ServicesForType", self.services_for_type),
            ("nodes", "Nodes", self.nodes),
            ("node_details", "NodeDetails", self.node_details),
            ("action_servers", "GetActionServers", self.action_servers),
            ("topic_type", "TopicType", self.topic_type),
            ("service_type", "ServiceType", self.service_type),
            ("publishers", "Publishers", self.publishers),
            ("subscribers", "Subscribers", self.subscribers),
            ("service_providers", "ServiceProviders", self.service_providers),
            ("service_node", "ServiceNode", self.service_node),
            ("service_host", "ServiceHost", self.service_host),
            ("message_details", "MessageDetails", self.message_details),
            ("service_request_details", "ServiceRequestDetails", self.service_request_details),
            ("service_response_details", "ServiceResponseDetails", self.service_response_details),
            ("set_param", "SetParam", self.set_param),
            ("get_param", "GetParam", self.get_param),
            ("has_param", "HasParam", self.has_param),
            ("search_param", "SearchParam", self.search_param),
            ("delete_param", "DeleteParam", self.delete_param),
            ("get_param_names", "GetParamNames", self.get_param_names),
            ("get_time", "GetTime", self.get_time),
        ):
            self._servers.append(node.service("~" + name, get_service_class(f"rosapi/{srv}"), handler))

    # -- graph --------------------------------------------------------------------------------
    def _types(self) -> list[tuple[str, str]]:
        return [(p[0], p[1]) for p in self.master.get_topic_types()]

    def _state(self) -> Any:
        return self.master.get_system_state()

    def topics(self, _req: Any) -> Any:
        pairs = self._types()
        return {"topics": [t for t, _ in pairs], "types": [ty for _, ty in pairs]}

    def topics_for_type(self, req: Any) -> Any:
        return {"topics": [t for t, ty in self._types() if ty == req.type]}

    def topics_and_raw_types(self, _req: Any) -> Any:
        pairs = self._types()
        texts = []
        for _, ty in pairs:
            try:
                texts.append(get_message_class(ty)._full_text)
            except NinjemysError:
                texts.append("")
        return {
            "topics": [t for t, _ in pairs],
            "types": [ty for _, ty in pairs],
            "typedefs_full_text": texts,
        }

    def services(self, _req: Any) -> Any:
        return {"services": [s for s, _ in self._state()[2]]}

    def _service_type(self, service: str) -> str:
        try:
            return probe(service, self.master.lookup_service(service), timeout=2.0).get("type", "")
        except NinjemysError:
            return ""

    def services_for_type(self, req: Any) -> Any:
        return {"services": [s for s, _ in self._state()[2] if self._service_type(s) == req.type]}

    def nodes(self, _req: Any) -> Any:
        names: set[str] = set()
        for group in self._state():
            for _, nodes in group:
                names.update(nodes)
        return {"nodes": sorted(names)}

    def node_details(self, req: Any) -> Any:
        pubs, subs, srvs = self._state()
        return {
            "subscribing": [t for t, n in subs if req.node in n],
            "publishing": [t for t, n in pubs if req.node in n],
            "services": [s for s, n in srvs if req.node in n],
        }

    def action_servers(self, _req: Any) -> Any:
        topics = {t for t, _ in self._types()}
        found = []
        for topic in sorted(topics):
            if topic.endswith("/goal"):
                base = topic[: -len("/goal")]
                if all(f"{base}/{x}" in topics for x in ("cancel", "status", "result", "feedback")):
                    found.append(base)
        return {"action_servers": found}

    def topic_type(self, req: Any) -> Any:
        return {"type": dict(self._types()).get(req.topic, "")}

    def service_type(self, req: Any) -> Any:
        return {"type": self._service_type(req.service)}

    def publishers(self, req: Any) -> Any:
        return {"publishers": next((n for t, n in self._state()[0] if t == req.topic), [])}

    def subscribers(self, req: Any) -> Any:
        return {"subscribers": next((n for t, n in self._state()[1] if t == req.topic), [])}

    def service_providers(self, req: Any) -> Any:
        """The nodes providing a service of type ``req.service`` (rosapi's own reading of the field)."""
        providers: list[str] = []
        for service, nodes in self._state()[2]:
            if self._service_type(service) == req.service:
                providers.extend(n for n in nodes if n not in providers)
        return {"providers": providers}

    def service_node(self, req: Any) -> Any:
        return {"node": next((n[0] for s, n in self._state()[2] if s == req.service and n), "")}

    def service_host(self, req: Any) -> Any:
        try:
            return {"host": split_uri(self.master.lookup_service(req.service))[0]}
        except (NinjemysError, ValueError):
            return {"host": ""}

    def _typedefs(self, type_name: str) -> dict[str, Any]:
        typedef = get_message_class("rosapi/TypeDef")
        return {"typedefs": [typedef(**d) for d in typedefs(type_name)]}

    def message_details(self, req: Any) -> Any:
        return self._typedefs(req.type)

    def service_request_details(self, req: Any) -> Any:
        return self._typedefs(get_service_class(req.type)._request_class._type)

    def service_response_details(self, req: Any) -> Any:
        return self._typedefs(get_service_class(req.type)._response_class._type)

    # -- parameters ---------------------------------------------------------------------------
    def set_param(self, req: Any) -> Any:
        try:
            value = json.loads(req.value)
        except ValueError:
            value = req.value
        self.node.set_param(req.name, value)
        return {}

    def get_param(self, req: Any) -> Any:
        default = None
        if req.default != "":
            try:
                default = json.loads(req.default)
            except ValueError:
                default = req.default
        return {"value": json.dumps(self.node.get_param(req.name, default), default=_jsonable)}

    def has_param(self, req: Any) -> Any:
        return {"exists": self.node.has_param(req.name)}

    def search_param(self, req: Any) -> Any:
        return {"global_name": self.node.search_param(req.name) or ""}

    def delete_param(self, req: Any) -> Any:
        if self.node.has_param(req.name):
            self.node.delete_param(req.name)
        return {}

    def get_param_names(self, _req: Any) -> Any:
        return {"names": self.node.get_param_names()}

    def get_time(self, _req: Any) -> Any:
        secs, nsecs = self.clock.now_pair()
        return {"time": Time(secs, nsecs)}

    def shutdown(self) -> None:
        for server in self._servers:
            server.shutdown()
        self.clock.shutdown()


def _jsonable(value: Any) -> Any:
    if isinstance(value, bytes | bytearray):
        import base64

        return base64.b64encode(bytes(value)).decode("ascii")
    return str(value)


def main(argv: list[str] | None = None) -> int:
    """``rosrun rosapi rosapi_node``."""
    from ninjemys.node.cli_args import parse_args

    args = parse_args([sys.argv[0], *(sys.argv[1:] if argv is None else argv)])
    name = args.node_name("rosapi")
    node = Node(
        name,
        namespace=args.namespace,
        remappings=args.resolved_remappings(args.full_name(name)),
        master_uri=args.master_uri,
        params=args.private_params,
    )
    RosApi(node)
    try:
        node.spin()
    except KeyboardInterrupt:
        pass
    finally:
        node.shutdown("rosapi exiting")
    return 0

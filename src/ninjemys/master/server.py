"""The XML-RPC face of the master: the Master API and the Parameter Server API, as rosmaster answers them.

Every call is checked the way rosmaster's ``apivalidate`` does it, with the same replies, so real
ROS 1 clients see no difference: ``[-1, "missing required caller_id parameter", v]``,
``[-1, "Error: bad call arity", v]``, ``[-1, "caller_id must be a string", v]``, per-argument
``[-1, "ERROR: parameter [topic] ...", v]``, ``[-1, "Error: invalid arguments: ...", v]`` for type
errors inside a method and ``[0, "Internal failure: ...", v]`` for anything else, where ``v`` is the
method's documented error value. Names are resolved relative to the caller (``chatter`` from
``/ns/talker`` is ``/ns/chatter``). An unknown method is an XML-RPC fault, as in rosmaster.

State lives in :class:`~ninjemys.master.store.RegistrationStore` and
:class:`~ninjemys.master.params.ParamTree`; notifications to nodes go through the asynchronous
:class:`~ninjemys.master.notify.Notifier`, so no call here ever waits for a node.
"""

from __future__ import annotations

import logging
import os
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from ninjemys.master.notify import Notifier
from ninjemys.master.params import ParamTree, compute_updates, subscription_key
from ninjemys.master.store import ANYTYPE, Bumped, RegistrationStore, Superseded
from ninjemys.names import resolve_name
from ninjemys.wire import xmlrpc as wire

log = logging.getLogger("ninjemys.master")


class _Invalid(Exception):
    """An argument failed validation; the message is rosmaster's."""


Validator = Callable[[Any, str], Any]


def _is_str(value: Any) -> bool:
    return isinstance(value, str)


def non_empty_str(name: str) -> Validator:
    def check(value: Any, caller_id: str) -> Any:
        if not value:
            raise _Invalid(f"ERROR: parameter [{name}] must be specified and non-empty")
        if not _is_str(value):
            raise _Invalid(f"ERROR: parameter [{name}] must be a string")
        return value

    return check


def not_none(name: str) -> Validator:
    def check(value: Any, caller_id: str) -> Any:
        if value is None:
            raise _Invalid(f"ERROR: parameter [{name}] must be specified")
        return value

    return check


def is_api(name: str) -> Validator:
    def check(value: Any, caller_id: str) -> Any:
        if not value or not _is_str(value):
            raise _Invalid(f"ERROR: parameter [{name}] is not an XMLRPC URI")
        if not value.startswith("http://") and not value.startswith("rosrpc://"):
            raise _Invalid(f"ERROR: parameter [{name}] is not an RPC URI")
        return value

    return check


def _valid_name(name: str, value: Any, caller_id: str) -> str:
    if not value or not _is_str(value):
        raise _Invalid(f"ERROR: parameter [{name}] must be a non-empty string")
    if ":" in value or " " in value:
        raise _Invalid(f"ERROR: parameter [{name}] contains illegal chars")
    return resolve_name(value, caller_id)


def valid_name(name: str) -> Validator:
    return lambda value, caller_id: _valid_name(name, value, caller_id)


def is_graph_resource(name: str) -> Validator:
    """A topic or service: a valid name that is not the root namespace."""

    def check(value: Any, caller_id: str) -> Any:
        resolved = _valid_name(name, value, caller_id)
        if value == "/":
            raise _Invalid(f"ERROR: parameter [{name}] cannot be the global namespace")
        return resolved

    return check


def empty_or_valid_name(name: str) -> Validator:
    def check(value: Any, caller_id: str) -> Any:
        if not _is_str(value):
            raise _Invalid(f"ERROR: parameter [{name}] must be a string")
        return resolve_name(value, caller_id) if value else ""

    return check


def valid_type_name(name: str) -> Validator:
    def check(value: Any, caller_id: str) -> Any:
        if value == ANYTYPE:
            return value
        if not value or not _is_str(value):
            raise _Invalid(f"ERROR: parameter [{name}] must be a non-empty string")
        if len(value.split("/")) != 2:
            raise _Invalid(f"ERROR: parameter [{name}] is not a valid package resource name")
        return value

    return check


#: calls that may change getSystemState's answer (a name clash can drop topics, even via subscribeParam)
_CHANGES_GRAPH = frozenset(
    {
        "registerService",
        "unregisterService",
        "registerSubscriber",
        "unregisterSubscriber",
        "registerPublisher",
        "unregisterPublisher",
        "subscribeParam",
        "unsubscribeParam",
    }
)


@dataclass(frozen=True)
class _Api:
    fn: Callable[..., list[Any]]
    error_value: Any
    validators: tuple[Validator | None, ...]


class MasterHandler:
    """The master's RPC methods, dispatched by :class:`~ninjemys.net.xmlrpc_server.XmlRpcServer`.

    ``on_shutdown(reason)`` is called when a client invokes ``shutdown``; ``uri`` is what ``getUri``
    answers (set it once the server is bound).
    """

    def __init__(
        self,
        notifier: Notifier | None = None,
        on_shutdown: Callable[[str], None] | None = None,
        uri: str = "",
    ) -> None:
        self.uri = uri
        self.store = RegistrationStore()
        self.params = ParamTree()
        self.notifier = notifier or Notifier(on_param_rejected=self._param_rejected)
        self.on_shutdown = on_shutdown
        self._state_cache: wire.Marshalled | None = None
        nn = non_empty_str
        self._apis: dict[str, _Api] = {
            "shutdown": _Api(self.shutdown, 0, (None,)),
            "getUri": _Api(self.getUri, "", ()),
            "getPid": _Api(self.getPid, -1, ()),
            "deleteParam": _Api(self.deleteParam, 0, (nn("key"),)),
            "setParam": _Api(self.setParam, 0, (nn("key"), not_none("value"))),
            "getParam": _Api(self.getParam, 0, (nn("key"),)),
            "searchParam": _Api(self.searchParam, 0, (nn("key"),)),
            "subscribeParam": _Api(self.subscribeParam, 0, (is_api("caller_api"), nn("key"))),
            "unsubscribeParam": _Api(self.unsubscribeParam, 0, (is_api("caller_api"), nn("key"))),
            "hasParam": _Api(self.hasParam, False, (nn("key"),)),
            "getParamNames": _Api(self.getParamNames, [], ()),
            "registerService": _Api(
                self.registerService,
                0,
                (is_graph_resource("service"), is_api("service_api"), is_api("caller_api")),
            ),
            "lookupService": _Api(self.lookupService, "", (is_graph_resource("service"),)),
            "unregisterService": _Api(
                self.unregisterService, 0, (is_graph_resource("service"), is_api("service_api"))
            ),
            "registerSubscriber": _Api(
                self.registerSubscriber,
                [],
                (is_graph_resource("topic"), valid_type_name("topic_type"), is_api("caller_api")),
            ),
            "unregisterSubscriber": _Api(
                self.unregisterSubscriber, 0, (is_graph_resource("topic"), is_api("caller_api"))
            ),
            "registerPublisher": _Api(
                self.registerPublisher,
                [],
                (is_graph_resource("topic"), valid_type_name("topic_type"), is_api("caller_api")),
            ),
            "unregisterPublisher": _Api(
                self.unregisterPublisher, 0, (is_graph_resource("topic"), is_api("caller_api"))
            ),
            "lookupNode": _Api(self.lookupNode, "", (valid_name("node"),)),
            "getPublishedTopics": _Api(self.getPublishedTopics, 0, (empty_or_valid_name("subgraph"),)),
            "getTopicTypes": _Api(self.getTopicTypes, [], ()),
            "getSystemState": _Api(self.getSystemState, [[], [], []], ()),
        }

    # -------------------------------------------------------------------------------- dispatch

    def _dispatch(self, method: str, params: tuple[Any, ...]) -> list[Any]:
        api = self._apis.get(method)
        if api is None:
            raise wire.Fault(1, f"<class 'Exception'>:method \"{method}\" is not supported")
        if not params:
            return [-1, "missing required caller_id parameter", api.error_value]
        if method in _CHANGES_GRAPH:
            self._state_cache = None
        if len(params) != len(api.validators) + 1:
            return [-1, "Error: bad call arity", api.error_value]
        caller_id = params[0]
        if not isinstance(caller_id, str):
            return [-1, "caller_id must be a string", api.error_value]
        args: list[Any] = [caller_id]
        try:
            for validator, value in zip(api.validators, params[1:], strict=True):
                args.append(value if validator is None else validator(value, caller_id))
        except _Invalid as exc:
            return [-1, str(exc) or "error", api.error_value]
        try:
            return api.fn(*args)
        except Superseded as exc:
            return [-1, str(exc), api.error_value]
        except TypeError as exc:
            return [-1, f"Error: invalid arguments: {exc}", api.error_value]
        except Exception as exc:
            log.exception("master: %s failed", method)
            return [0, f"Internal failure: {exc}", api.error_value]

    # ------------------------------------------------------------------------------- process

    def shutdown(self, caller_id: str, msg: str = "") -> list[Any]:
        log.info("shutdown request from [%s]: %s", caller_id, msg)
        if self.on_shutdown is not None:
            self.on_shutdown(f"external shutdown request from [{caller_id}]: {msg}")
        return [1, "shutdown", 0]

    def getUri(self, caller_id: str) -> list[Any]:
        return [1, "", self.uri]

    def getPid(self, caller_id: str) -> list[Any]:
        return [1, "", os.getpid()]

    # ------------------------------------------------------------------------ parameter server

    def deleteParam(self, caller_id: str, key: str) -> list[Any]:
        key = resolve_name(key, caller_id)
        try:
            self.params.delete(key)
        except KeyError:
            return [-1, f"parameter [{key}] is not set", 0]
        self._notify_params(compute_updates(self.store.param_subscribers.map, key, {}))
        log.info("-PARAM [%s] by %s", key, caller_id)
        return [1, f"parameter {key} deleted", 0]

    def setParam(self, caller_id: str, key: str, value: Any) -> list[Any]:
        key = resolve_name(key, caller_id)
        self.params.set(key, value)
        self._notify_params(compute_updates(self.store.param_subscribers.map, key, value, caller_id))
        log.info("+PARAM [%s] by %s", key, caller_id)
        return [1, f"parameter {key} set", 0]

    def getParam(self, caller_id: str, key: str) -> list[Any]:
        key = resolve_name(key, caller_id)
        try:
            return [1, f"Parameter [{key}]", self.params.get(key)]
        except KeyError:
            return [-1, f"Parameter [{key}] is not set", 0]

    def searchParam(self, caller_id: str, key: str) -> list[Any]:
        found = self.params.search(caller_id, key)
        if found:
            return [1, f"Found [{found}]", found]
        return [-1, f"Cannot find parameter [{key}] in an upwards search", ""]

    def subscribeParam(self, caller_id: str, caller_api: str, key: str) -> list[Any]:
        key = resolve_name(key, caller_id)
        try:
            value = self.params.get(key)
        except KeyError:
            value = {}
        self.notifier.revive(caller_api)
        bumped = self.store.register_param_subscriber(subscription_key(key), caller_id, caller_api)
        self._bump(bumped)
        log.info("+CACHEDPARAM [%s] by %s", key, caller_id)
        return [1, f"Subscribed to parameter [{key}]", value]

    def unsubscribeParam(self, caller_id: str, caller_api: str, key: str) -> list[Any]:
        key = resolve_name(key, caller_id)
        self.store.unregister_param_subscriber(subscription_key(key), caller_id, caller_api)
        log.info("-CACHEDPARAM [%s] by %s", key, caller_id)
        return [1, f"Unsubscribe to parameter [{key}]", 1]

    def hasParam(self, caller_id: str, key: str) -> list[Any]:
        key = resolve_name(key, caller_id)
        return [1, key, self.params.has(key)]

    def getParamNames(self, caller_id: str) -> list[Any]:
        return [1, "Parameter names", self.params.names()]

    def _notify_params(self, updates: list[tuple[list[tuple[str, str]], str, Any]]) -> None:
        for subscribers, key, value in updates:
            if not subscribers:
                continue
            if type(value) is dict or type(value) is list:
                # snapshot now: the tree may change before the update is sent (rosmaster sends a live
                # reference and can tell a node a later value); rendered once for all subscribers
                value = wire.Marshalled(value)
            for _, api in subscribers:
                self.notifier.param_update(api, key, value)

    def _param_rejected(self, api: str, key: str) -> None:
        """A node answered paramUpdate with -1: forget its subscription (ROS 1 does the same)."""
        for node in list(self.store.nodes.values()):
            if node.api == api:
                self.store.unregister_param_subscriber(key, node.name, api)

    # -------------------------------------------------------------------------------- services

    def registerService(self, caller_id: str, service: str, service_api: str, caller_api: str) -> list[Any]:
        self.notifier.revive(caller_api)
        self._bump(self.store.register_service(service, service_api, caller_id, caller_api))
        log.info("+SERVICE [%s] %s %s", service, caller_id, caller_api)
        return [1, f"Registered [{caller_id}] as provider of [{service}]", 1]

    def lookupService(self, caller_id: str, service: str) -> list[Any]:
        uri = self.store.lookup_service(service)
        if uri:
            return [1, f"rosrpc URI: [{uri}]", uri]
        return [-1, "no provider", ""]

    def unregisterService(self, caller_id: str, service: str, service_api: str) -> list[Any]:
        message, count = self.store.unregister_service(service, service_api, caller_id)
        log.info("-SERVICE [%s] %s %s", service, caller_id, service_api)
        return [1, message, count]

    # ---------------------------------------------------------------------------------- topics

    def registerSubscriber(self, caller_id: str, topic: str, topic_type: str, caller_api: str) -> list[Any]:
        self.notifier.revive(caller_api)
        self._bump(self.store.register_subscriber(topic, topic_type, caller_id, caller_api))
        log.info("+SUB [%s] %s %s", topic, caller_id, caller_api)
        return [1, f"Subscribed to [{topic}]", self.store.publishers.apis(topic)]

    def unregisterSubscriber(self, caller_id: str, topic: str, caller_api: str) -> list[Any]:
        message, count = self.store.unregister_subscriber(topic, caller_id, caller_api)
        log.info("-SUB [%s] %s %s", topic, caller_id, caller_api)
        return [1, message, count]

    def registerPublisher(self, caller_id: str, topic: str, topic_type: str, caller_api: str) -> list[Any]:
        self.notifier.revive(caller_api)
        self._bump(self.store.register_publisher(topic, topic_type, caller_id, caller_api))
        self._notify_topic(topic)
        log.info("+PUB [%s] %s %s", topic, caller_id, caller_api)
        return [1, f"Registered [{caller_id}] as publisher of [{topic}]", self.store.subscribers.apis(topic)]

    def unregisterPublisher(self, caller_id: str, topic: str, caller_api: str) -> list[Any]:
        message, count = self.store.unregister_publisher(topic, caller_id, caller_api)
        if count:
            self._notify_topic(topic)
        log.info("-PUB [%s] %s %s", topic, caller_id, caller_api)
        return [1, message, count]

    def _notify_topic(self, topic: str) -> None:
        publishers = self.store.publishers.apis(topic)
        for api in self.store.subscribers.apis(topic):
            self.notifier.publisher_update(api, topic, publishers)

    def _bump(self, bumped: Bumped | None) -> None:
        """A name was taken over: shut the old process down and tell its topics' subscribers."""
        if bumped is None:
            return
        log.warning("new node registered with same name [%s]; shutting down %s", bumped.name, bumped.api)
        self.notifier.shutdown_node(bumped.api, f"[{bumped.name}] Reason: new node registered with same name")
        for topic in bumped.publications:
            self._notify_topic(topic)

    # ----------------------------------------------------------------------------------- graph

    def lookupNode(self, caller_id: str, node_name: str) -> list[Any]:
        api = self.store.lookup_node(node_name)
        if api is not None:
            return [1, "node api", api]
        return [-1, f"unknown node [{node_name}]", ""]

    def getPublishedTopics(self, caller_id: str, subgraph: str) -> list[Any]:
        if subgraph and not subgraph.endswith("/"):
            subgraph += "/"
        return [1, "current topics", self.store.published_topics(subgraph)]

    def getTopicTypes(self, caller_id: str) -> list[Any]:
        return [1, "current system state", [[t, ty] for t, ty in self.store.topic_types.items()]]

    def getSystemState(self, caller_id: str) -> list[Any]:
        # rosnode, rostopic, rqt_graph and the web UI poll this: render it once per graph change
        if self._state_cache is None:
            self._state_cache = wire.Marshalled(self.store.system_state())
        return [1, "current system state", self._state_cache]

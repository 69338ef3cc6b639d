"""Registrations of the ROS graph: nodes, publishers, subscribers, services, parameter subscribers.

Pure data, no I/O and no locks (the master runs it on one event loop). Semantics follow rosmaster:

* A node is known by name (caller_id) and XML-RPC API. Registering anything under a known name but a
  different API *replaces* the node: all of the old node's registrations are dropped and the caller
  learns the old API (the master then asks the old process to shut down).
* A node that lost its name is told to shut down, but a dying rospy node keeps calling the master for a
  moment (it re-subscribes an unset parameter on every log message). rosmaster lets such a late call
  take the name back and shut the *new* node down - two nodes die instead of one. Here a replaced
  (name, API) pair cannot register again for ``SUPERSEDED_SECONDS``: its calls raise
  :class:`Superseded` (the master answers -1) and the new node keeps its name.
* A node that unregistered everything is forgotten (``lookupNode`` fails for it).
* Topic registrations are multimaps keyed by name, kept in first-registration order (which
  ``getSystemState`` reports); a service has exactly one provider, the latest to register.
* ``*`` as a topic type never overwrites a known type; a subscriber only records a type if the topic
  had none.

Entries are dicts used as ordered sets, so registering, unregistering and looking up are O(1) and a
graph of thousands of nodes costs nothing per call but the answer's size.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

ANYTYPE = "*"
SUPERSEDED_SECONDS = 30.0


class Superseded(Exception):
    """A registration from a node whose name was taken over by a newer node."""


Entry = tuple[str, str]  # (caller_id, caller_api)


class Registrations:
    """One kind of registration: key -> ordered set of (caller_id, caller_api)."""

    def __init__(self) -> None:
        self.map: dict[str, dict[Entry, None]] = {}

    def register(self, key: str, caller_id: str, caller_api: str) -> None:
        self.map.setdefault(key, {})[(caller_id, caller_api)] = None

    def replace(self, key: str, caller_id: str, caller_api: str) -> None:
        """Make ``caller_id`` the only entry for ``key`` (services)."""
        self.map[key] = {(caller_id, caller_api): None}

    def unregister(self, key: str, caller_id: str, caller_api: str) -> bool:
        entries = self.map.get(key)
        if entries is None or (caller_id, caller_api) not in entries:
            return False
        del entries[(caller_id, caller_api)]
        if not entries:
            del self.map[key]
        return True

    def unregister_node(self, caller_id: str, keys: set[str]) -> list[str]:
        """Drop every entry of ``caller_id`` under ``keys``; returns the keys that changed."""
        changed = []
        for key in keys:
            entries = self.map.get(key)
            if not entries:
                continue
            dead = [entry for entry in entries if entry[0] == caller_id]
            for entry in dead:
                del entries[entry]
            if dead:
                changed.append(key)
            if not entries:
                del self.map[key]
        return changed

    def apis(self, key: str) -> list[str]:
        return [api for _, api in self.map.get(key, ())]

    def entries(self, key: str) -> list[Entry]:
        return list(self.map.get(key, ()))

    def state(self) -> list[list[object]]:
        """``[[key, [caller_id, ...]], ...]`` as getSystemState reports it."""
        return [[key, [caller_id for caller_id, _ in entries]] for key, entries in self.map.items()]

    def __contains__(self, key: object) -> bool:
        return key in self.map


@dataclass
class NodeRef:
    """What the master knows about one node."""

    name: str
    api: str
    publications: set[str] = field(default_factory=set)
    subscriptions: set[str] = field(default_factory=set)
    services: set[str] = field(default_factory=set)
    param_subscriptions: set[str] = field(default_factory=set)

    def is_empty(self) -> bool:
        return not (self.publications or self.subscriptions or self.services or self.param_subscriptions)


@dataclass
class Bumped:
    """A node that lost its name to a new registration, and the topics it was publishing."""

    name: str
    api: str
    publications: list[str]


class RegistrationStore:
    """Every registration of the graph, with rosmaster's rules."""

    def __init__(self) -> None:
        self.nodes: dict[str, NodeRef] = {}
        self.publishers = Registrations()
        self.subscribers = Registrations()
        self.services = Registrations()
        self.service_apis: dict[str, Entry] = {}  # service -> (caller_id, rosrpc uri)
        self.param_subscribers = Registrations()
        self.topic_types: dict[str, str] = {}
        self._had_service = False  # rosmaster words one reply differently before the first service
        self._superseded: dict[Entry, float] = {}  # (name, api) -> when it was replaced

    # ----------------------------------------------------------------------------------- nodes

    def _node_for(self, caller_id: str, caller_api: str) -> tuple[NodeRef, Bumped | None]:
        node = self.nodes.get(caller_id)
        if node is not None and node.api == caller_api:
            return node, None
        if self._superseded:
            self._check_superseded(caller_id, caller_api)
        bumped = None
        if node is not None:
            self._superseded[(node.name, node.api)] = time.monotonic()
            bumped = Bumped(node.name, node.api, sorted(node.publications))
            self.publishers.unregister_node(caller_id, node.publications)
            self.subscribers.unregister_node(caller_id, node.subscriptions)
            self.param_subscribers.unregister_node(caller_id, node.param_subscriptions)
            for service in node.services:
                self.services.unregister_node(caller_id, {service})
                if self.service_apis.get(service, ("",))[0] == caller_id:
                    del self.service_apis[service]
        node = NodeRef(caller_id, caller_api)
        self.nodes[caller_id] = node
        return node, bumped

    def _check_superseded(self, caller_id: str, caller_api: str) -> None:
        now = time.monotonic()
        when = self._superseded.get((caller_id, caller_api))
        if when is not None and now - when < SUPERSEDED_SECONDS:
            raise Superseded(
                f"node [{caller_id}] at {caller_api} was replaced by a newer node with the same name; "
                "it has been asked to shut down"
            )
        if len(self._superseded) > 64 or when is not None:
            self._superseded = {k: t for k, t in self._superseded.items() if now - t < SUPERSEDED_SECONDS}

    def _forget_if_empty(self, node: NodeRef) -> None:
        if node.is_empty() and self.nodes.get(node.name) is node:
            del self.nodes[node.name]

    def lookup_node(self, name: str) -> str | None:
        node = self.nodes.get(name)
        return None if node is None else node.api

    # ---------------------------------------------------------------------------------- topics

    def register_publisher(
        self, topic: str, topic_type: str, caller_id: str, caller_api: str
    ) -> Bumped | None:
        node, bumped = self._node_for(caller_id, caller_api)
        node.publications.add(topic)
        self.publishers.register(topic, caller_id, caller_api)
        if topic_type != ANYTYPE or topic not in self.topic_types:
            self.topic_types[topic] = topic_type
        return bumped

    def register_subscriber(
        self, topic: str, topic_type: str, caller_id: str, caller_api: str
    ) -> Bumped | None:
        node, bumped = self._node_for(caller_id, caller_api)
        node.subscriptions.add(topic)
        self.subscribers.register(topic, caller_id, caller_api)
        if topic not in self.topic_types and topic_type != ANYTYPE:
            self.topic_types[topic] = topic_type
        return bumped

    def unregister_publisher(self, topic: str, caller_id: str, caller_api: str) -> tuple[str, int]:
        return self._unregister(self.publishers, "publications", topic, caller_id, caller_api)

    def unregister_subscriber(self, topic: str, caller_id: str, caller_api: str) -> tuple[str, int]:
        return self._unregister(self.subscribers, "subscriptions", topic, caller_id, caller_api)

    def _unregister(
        self, regs: Registrations, attr: str, key: str, caller_id: str, caller_api: str
    ) -> tuple[str, int]:
        node = self.nodes.get(caller_id)
        if node is None:
            return f"[{caller_id}] is not a registered node", 0
        if not regs.unregister(key, caller_id, caller_api):
            self._forget_if_empty(node)
            return f"[{caller_id}] is not a known provider of [{key}]", 0
        getattr(node, attr).discard(key)
        self._forget_if_empty(node)
        return f"Unregistered [{caller_id}] as provider of [{key}]", 1

    # -------------------------------------------------------------------------------- services

    def register_service(
        self, service: str, service_api: str, caller_id: str, caller_api: str
    ) -> Bumped | None:
        node, bumped = self._node_for(caller_id, caller_api)
        node.services.add(service)
        self.services.replace(service, caller_id, caller_api)
        self.service_apis[service] = (caller_id, service_api)
        self._had_service = True
        return bumped

    def unregister_service(self, service: str, service_api: str, caller_id: str) -> tuple[str, int]:
        node = self.nodes.get(caller_id)
        if node is None:
            return f"[{caller_id}] is not a registered node", 0
        if not self._had_service:
            self._forget_if_empty(node)
            return f"[{caller_id}] is not a provider of [{service}]", 0
        if self.service_apis.get(service) != (caller_id, service_api):
            self._forget_if_empty(node)
            return f"[{service_api}] is no longer the current service api handle for [{service}]", 0
        del self.service_apis[service]
        self.services.map.pop(service, None)
        node.services.discard(service)
        self._forget_if_empty(node)
        return f"Unregistered [{caller_id}] as provider of [{service}]", 1

    def lookup_service(self, service: str) -> str | None:
        entry = self.service_apis.get(service)
        return None if entry is None else entry[1]

    # ---------------------------------------------------------------------- parameter subscribers

    def register_param_subscriber(self, key: str, caller_id: str, caller_api: str) -> Bumped | None:
        node, bumped = self._node_for(caller_id, caller_api)
        node.param_subscriptions.add(key)
        self.param_subscribers.register(key, caller_id, caller_api)
        return bumped

    def unregister_param_subscriber(self, key: str, caller_id: str, caller_api: str) -> int:
        return self._unregister(self.param_subscribers, "param_subscriptions", key, caller_id, caller_api)[1]

    # ----------------------------------------------------------------------------------- views

    def published_topics(self, prefix: str) -> list[list[str]]:
        return [[topic, self.topic_types[topic]] for topic in self.publishers.map if topic.startswith(prefix)]

    def system_state(self) -> list[list[list[object]]]:
        return [self.publishers.state(), self.subscribers.state(), self.services.state()]

"""rosgraph.masterapi: ROS 1's ``Master`` handle, each call returning the value of the master's
``[code, status, value]`` answer or raising MasterError (code -1: bad arguments) or MasterFailure
(code 0). An unreachable master raises the socket error itself (ConnectionRefusedError ...), as ROS 1's
xmlrpc.client does, because scripts catch ``socket.error`` around these calls."""

from __future__ import annotations

import errno
from typing import Any

from ninjemys.errors import MasterError as _CoreMasterError
from ninjemys.errors import MasterUnreachable
from ninjemys.master.client import MasterClient

from .names import make_caller_id
from .rosenv import get_master_uri


class MasterException(Exception):
    """Base class of the errors the master reports."""


class MasterFailure(MasterException):
    """The master failed (code 0): an internal error, its state may be inconsistent."""


class MasterError(MasterException):
    """The master refused the call's arguments (code -1)."""


# the names ROS 1 kept for backwards compatibility
ROSMasterException = MasterException
Error = MasterError
Failure = MasterFailure


def is_online(master_uri: str | None = None) -> bool:
    """True if a master answers at ``master_uri`` (default: the process's)."""
    return Master("rosgraph", master_uri=master_uri).is_online()


class _Handle:
    """``master.handle.method(*args)``: the raw XML-RPC call ROS 1 scripts reach through
    ``Master.handle`` (a ServerProxy there), returning the whole ``[code, status, value]``."""

    def __init__(self, client: MasterClient) -> None:
        self._client = client

    def __getattr__(self, method: str) -> Any:
        if method.startswith("_"):
            raise AttributeError(method)

        def call(*args: Any) -> Any:
            return _raw(self._client, method, args)

        return call


def _raw(client: MasterClient, method: str, args: tuple[Any, ...]) -> Any:
    try:
        return client.call_raw(method, *args)
    except MasterUnreachable as exc:
        text = str(exc)
        if "refused" in text:
            raise ConnectionRefusedError(errno.ECONNREFUSED, "Connection refused") from None
        raise OSError(text) from None
    except _CoreMasterError as exc:  # a broken answer: the master failed, not the arguments
        raise MasterFailure(str(exc)) from None


class Master:
    """The master's API as node ``caller_id`` (resolved in ROS_NAMESPACE, like ROS 1)."""

    def __init__(self, caller_id: str, master_uri: str | None = None) -> None:
        if master_uri is None:
            master_uri = get_master_uri()
        self._reinit(master_uri)
        self.caller_id = make_caller_id(caller_id)
        if self.caller_id[-1] == "/":
            self.caller_id = self.caller_id[:-1]

    def _reinit(self, master_uri: str) -> None:
        """Point this handle at another master (ROS 1 tools use it after ``__master:=``)."""
        self.master_uri = master_uri
        self._client = MasterClient(master_uri, timeout=None)
        self.handle = _Handle(self._client)

    def is_online(self) -> bool:
        """True if the master answers getPid."""
        try:
            self.getPid()
        except Exception:  # noqa: BLE001  (ROS 1: any failure means offline)
            return False
        return True

    def _succeed(self, args: Any) -> Any:
        code, msg, val = args
        if code == 1:
            return val
        if code == -1:
            raise MasterError(msg)
        raise MasterFailure(msg)

    def _call(self, method: str, *args: Any) -> Any:
        return self._succeed(_raw(self._client, method, (self.caller_id, *args)))

    # parameter server
    def deleteParam(self, key: str) -> int:  # noqa: N802  (ROS 1's method names)
        """Delete ``key`` (MasterError if it is not set)."""
        return self._call("deleteParam", key)

    def setParam(self, key: str, value: Any) -> int:  # noqa: N802
        """Set ``key``; a dict replaces the whole namespace ``key``."""
        return self._call("setParam", key, value)

    def getParam(self, key: str) -> Any:  # noqa: N802
        """The value of ``key`` (a dict for a namespace); MasterError if unset."""
        return self._call("getParam", key)

    def searchParam(self, key: str) -> str:  # noqa: N802
        """The closest ``key`` up the caller's namespace (MasterError when none is set)."""
        return self._call("searchParam", key)

    def subscribeParam(self, caller_api: str, key: str) -> Any:  # noqa: N802
        """Subscribe ``caller_api`` to updates of ``key``; returns its current value."""
        return self._call("subscribeParam", caller_api, key)

    def unsubscribeParam(self, caller_api: str, key: str) -> int:  # noqa: N802
        """Undo subscribeParam."""
        return self._call("unsubscribeParam", caller_api, key)

    def hasParam(self, key: str) -> bool:  # noqa: N802
        """True if ``key`` is set."""
        return self._call("hasParam", key)

    def getParamNames(self) -> list[str]:  # noqa: N802
        """Every parameter name."""
        return self._call("getParamNames")

    # master
    def getPid(self) -> int:  # noqa: N802
        """The master's process id."""
        return self._call("getPid")

    def getUri(self) -> str:  # noqa: N802
        """The master's URI as it reports it."""
        return self._call("getUri")

    def registerService(self, service: str, service_api: str, caller_api: str) -> int:  # noqa: N802
        """Register the caller as the provider of ``service`` at ``service_api`` (rosrpc://)."""
        return self._call("registerService", service, service_api, caller_api)

    def lookupService(self, service: str) -> str:  # noqa: N802
        """The rosrpc:// URI of ``service``; MasterError if nobody provides it."""
        return self._call("lookupService", service)

    def unregisterService(self, service: str, service_api: str) -> int:  # noqa: N802
        """Undo registerService."""
        return self._call("unregisterService", service, service_api)

    def registerSubscriber(self, topic: str, topic_type: str, caller_api: str) -> list[str]:  # noqa: N802
        """Register a subscription; returns the publishers' XML-RPC URIs."""
        return self._call("registerSubscriber", topic, topic_type, caller_api)

    def unregisterSubscriber(self, topic: str, caller_api: str) -> int:  # noqa: N802
        """Undo registerSubscriber."""
        return self._call("unregisterSubscriber", topic, caller_api)

    def registerPublisher(self, topic: str, topic_type: str, caller_api: str) -> list[str]:  # noqa: N802
        """Register a publication; returns the subscribers' XML-RPC URIs."""
        return self._call("registerPublisher", topic, topic_type, caller_api)

    def unregisterPublisher(self, topic: str, caller_api: str) -> int:  # noqa: N802
        """Undo registerPublisher."""
        return self._call("unregisterPublisher", topic, caller_api)

    def lookupNode(self, node_name: str) -> str:  # noqa: N802
        """The XML-RPC URI of ``node_name``; MasterError for an unknown node."""
        return self._call("lookupNode", node_name)

    def getPublishedTopics(self, subgraph: str) -> list[list[str]]:  # noqa: N802
        """``[[topic, type], ...]`` of the published topics under ``subgraph``."""
        return self._call("getPublishedTopics", subgraph)

    def getTopicTypes(self) -> list[list[str]]:  # noqa: N802
        """``[[topic, type], ...]`` of every known topic."""
        return self._call("getTopicTypes")

    def getSystemState(self) -> list[list[list[Any]]]:  # noqa: N802
        """``[publishers, subscribers, services]``, each ``[[name, [node, ...]], ...]``."""
        return self._call("getSystemState")

"""rospy.get_master(): the master's XML-RPC API with this node's caller id filled in.

``rospy.get_master().getSystemState()`` returns the raw ``[code, statusMessage, value]`` triple, as in
rospy; ``master["key"]`` reads a parameter (KeyError when unset) and ``master["key"] = v`` sets one.
"""

from __future__ import annotations

from ninjemys.master.client import MasterClient

TYPE_CHECKING = False  # importing typing costs ~7 ms of every node's start-up; checkers set it
if TYPE_CHECKING:
    from typing import Any

__all__ = ["MasterProxy"]


class MasterProxy:
    """Forward ``proxy.method(*args)`` to the master as ``method(caller_id, *args)``."""

    def __init__(self, uri: str, caller_id: str, resolve: Any = None) -> None:
        self._client = MasterClient(uri, caller_id)
        self._caller_id = caller_id
        self._resolve = resolve or (lambda name: name)
        self.target = self

    def __getattr__(self, method: str) -> Any:
        if method.startswith("_"):
            raise AttributeError(method)

        def call(*args: Any) -> Any:
            return self._client.call_raw(method, self._caller_id, *args)

        return call

    def __getitem__(self, key: str) -> Any:
        code, _msg, value = self._client.call_raw("getParam", self._caller_id, self._resolve(key))
        if code != 1:
            raise KeyError(key)
        return value

    def __setitem__(self, key: str, value: Any) -> None:
        self._client.call_raw("setParam", self._caller_id, self._resolve(key), value)

    def __contains__(self, key: str) -> bool:
        code, _msg, value = self._client.call_raw("hasParam", self._caller_id, self._resolve(key))
        return code == 1 and bool(value)

    def search_param(self, key: str) -> str | None:
        code, _msg, value = self._client.call_raw("searchParam", self._caller_id, key)
        return value if code == 1 and value else None

    def get_param_names(self) -> list[str]:
        code, _msg, value = self._client.call_raw("getParamNames", self._caller_id)
        return list(value) if code == 1 else []

"""Parameter-server calls as a node makes them: names resolved by the caller, errors in our tree.

A mixin, because two callers need exactly the same behaviour: :class:`~ninjemys.node.Node`, and
rospy before ``init_node`` (rospy lets ``get_param`` & co. run as ``/unnamed``, so ``~x`` is
``/unnamed/x``). Whatever mixes it in provides ``master`` (a MasterClient) and ``resolve_name``.
"""

from __future__ import annotations

from ninjemys.errors import MasterError, ParameterError

TYPE_CHECKING = False  # importing typing costs ~7 ms of every node's start-up; checkers set it
if TYPE_CHECKING:
    from collections.abc import Callable
    from typing import Any

    from ninjemys.master.client import MasterClient

_UNSET = object()
#: the master's codes for "no such parameter" (as opposed to an unreachable master)
_NOT_SET = (-1, 0)


class ParamAccess:
    """get/set/has/delete/search parameters and list their names, through ``self.master``."""

    master: MasterClient
    resolve_name: Callable[[str], str]

    def get_param(self, key: str, default: Any = _UNSET) -> Any:
        """The value of ``key`` (resolved like a topic name); ``default`` if unset, else ParameterError."""
        resolved = self.resolve_name(key)
        try:
            return self.master.get_param(resolved)
        except MasterError as exc:
            if getattr(exc, "code", None) not in _NOT_SET:
                raise  # unreachable master, protocol trouble: not "unset"
            if default is not _UNSET:
                return default
            raise ParameterError(f"parameter [{resolved}] is not set") from None

    def set_param(self, key: str, value: Any) -> None:
        self.master.set_param(self.resolve_name(key), value)

    def has_param(self, key: str) -> bool:
        return bool(self.master.has_param(self.resolve_name(key)))

    def delete_param(self, key: str) -> None:
        resolved = self.resolve_name(key)
        try:
            self.master.delete_param(resolved)
        except MasterError as exc:
            if getattr(exc, "code", None) in _NOT_SET:
                raise ParameterError(f"parameter [{resolved}] is not set") from None
            raise

    def search_param(self, key: str) -> str | None:
        try:
            return self.master.search_param(key)
        except MasterError as exc:
            if getattr(exc, "code", None) in _NOT_SET:
                return None
            raise

    def get_param_names(self) -> list[str]:
        return list(self.master.get_param_names())

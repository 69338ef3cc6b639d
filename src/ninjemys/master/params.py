"""The parameter tree: a nested dict addressed by global graph names, with ROS 1's semantics.

Pure data, no I/O and no locks: the master serialises access by running everything on its event loop.

* ``set(key, dict)`` *replaces* the subtree at ``key`` (no merge); setting below a leaf turns the leaf
  into a namespace; ``set("/", d)`` replaces the whole tree (``d`` must be a dict).
* ``get`` of a namespace returns the nested dict; a missing key raises ``KeyError``.
* ``search(caller_id, key)`` walks up from the caller's *name* (so ``/pr2/foo`` looks in
  ``/pr2/foo/``, ``/pr2/``, ``/``) for the first namespace holding the key's first segment and returns
  the full key there, which may not exist yet (``/pr2/robot_description/arm``).
* :func:`compute_updates` decides which ``paramUpdate`` notifications a change causes: subscribers at
  or above the changed key get the new value (the caller itself excepted), subscribers below a
  replaced subtree get their new sub-value, or ``{}`` if the new tree no longer holds their key.
  Subscription keys are stored with a trailing ``/``, exactly as ROS 1 sends them.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from typing import Any

SEP = "/"

#: one subscription: (caller_id, caller_api)
Subscriber = tuple[str, str]
#: (subscribers to notify, key with trailing slash, value; ``{}`` = deleted)
Update = tuple[list[Subscriber], str, Any]


def _segments(key: str) -> list[str]:
    return [part for part in key.split(SEP) if part]


def subscription_key(key: str) -> str:
    """The stored form of a subscribed key: canonical, with a trailing ``/`` (``/`` stays ``/``)."""
    if key == SEP:
        return key
    return SEP + SEP.join(_segments(key)) + SEP


class ParamTree:
    """The parameter server's storage."""

    def __init__(self) -> None:
        self.root: dict[str, Any] = {}

    def get(self, key: str) -> Any:
        """The value at ``key`` (a dict for a namespace); ``KeyError`` if unset."""
        node: Any = self.root
        for part in _segments(key):
            if type(node) is not dict:
                raise KeyError(key)
            node = node[part]
        return node

    def has(self, key: str) -> bool:
        try:
            self.get(key)
        except KeyError:
            return False
        return True

    def set(self, key: str, value: Any) -> None:
        """Store ``value`` at ``key``, creating (or overwriting leaves with) namespaces on the way."""
        parts = _segments(key)
        if not parts:
            if type(value) is not dict:
                raise TypeError("cannot set root of parameter tree to non-dictionary")
            self.root = value
            return
        node = self.root
        for part in parts[:-1]:
            child = node.get(part)
            if type(child) is not dict:
                child = {}
                node[part] = child
            node = child
        node[parts[-1]] = value

    def delete(self, key: str) -> None:
        """Remove ``key`` (and its subtree); ``KeyError`` if unset or the root."""
        parts = _segments(key)
        if not parts:
            raise KeyError("cannot delete root of parameter tree")
        node: Any = self.root
        for part in parts[:-1]:
            if type(node) is not dict or part not in node:
                raise KeyError(key)
            node = node[part]
        if type(node) is not dict or parts[-1] not in node:
            raise KeyError(key)
        del node[parts[-1]]

    def names(self) -> list[str]:
        """Every leaf's full name (namespaces are not listed, as in ROS 1)."""
        out: list[str] = []
        # depth-first in insertion order (the order rosmaster lists them), without recursion
        stack: list[tuple[str, Any]] = [(SEP + name, value) for name, value in reversed(self.root.items())]
        while stack:
            full, value = stack.pop()
            if type(value) is dict:
                stack.extend((full + SEP + name, child) for name, child in reversed(value.items()))
            else:
                out.append(full)
        return out

    def search(self, caller_id: str, key: str) -> str | None:
        """ROS 1's upward search; ``None`` when nothing matches. ``ValueError`` for unusable input."""
        if not key or key.startswith("~"):
            raise ValueError("invalid key")
        if not caller_id.startswith(SEP):
            raise ValueError("namespace must be global")
        if key.startswith(SEP):
            return key if self.has(key) else None
        key_parts = _segments(key)
        first = key_parts[0]
        namespaces = _segments(caller_id)
        for depth in range(len(namespaces), -1, -1):
            base = namespaces[:depth]
            if self.has(SEP + SEP.join(base + [first])):
                return SEP + SEP.join(base + [key])
        return None


def _subtree_keys(prefix: str, tree: Mapping[str, Any], out: dict[str, Any]) -> None:
    """Every key inside ``tree`` (with trailing ``/``) mapped to its value."""
    for name, value in tree.items():
        full = prefix + name + SEP
        out[full] = value
        if type(value) is dict:
            _subtree_keys(full, value, out)


def compute_updates(
    subscriptions: Mapping[str, Iterable[Subscriber]],
    key: str,
    value: Any,
    ignore_caller: str | None = None,
) -> list[Update]:
    """The ``paramUpdate`` calls that setting ``key`` to ``value`` requires (``{}`` for a delete)."""
    if not subscriptions:
        return []
    key = subscription_key(key)
    inner: dict[str, Any] | None = None
    if type(value) is dict:
        inner = {}
        _subtree_keys(key, value, inner)
    updates: list[Update] = []
    for sub_key, subscribers in subscriptions.items():
        if key.startswith(sub_key):
            targets = [s for s in subscribers if s[0] != ignore_caller]
            if targets:
                updates.append((targets, key, value))
        elif inner is not None and sub_key.startswith(key):
            updates.append((list(subscribers), sub_key, inner.get(sub_key, {})))
    return updates

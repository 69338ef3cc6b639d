"""Userdata: the key/value blackboard states share, and the per-state view that enforces declarations.

A state never sees its container's :class:`UserData` directly: it gets a :class:`Remapper` that
renames keys (the ``remapping`` given to ``add``), refuses reads of undeclared input keys with
:class:`~ninjemys.smach.errors.InvalidUserCodeError`, ignores (and logs) writes to undeclared output
keys, and hands input-only values out read-only.
"""

from __future__ import annotations

import copy
import threading
from collections.abc import Iterable, Mapping
from typing import Any

from ninjemys.smach.errors import InvalidUserCodeError
from ninjemys.smach.log import logdebug, logerr

__all__ = ["Const", "Remapper", "UserData", "get_const"]


class UserData:
    """A dict with attribute access (``ud.x`` == ``ud['x']``), safe to use from concurrent states."""

    def __init__(self) -> None:
        object.__setattr__(self, "_data", {})
        object.__setattr__(self, "_lock", threading.Lock())

    def update(self, other_userdata: UserData) -> None:
        """Copy every key of ``other_userdata`` in, overwriting duplicates."""
        with self._lock:
            self._data.update(other_userdata._data)

    def extract(self, keys: Iterable[str], remapping: Mapping[str, str]) -> UserData:
        """A new UserData holding shallow copies of ``keys``, named back through ``remapping``."""
        reverse = {v: k for k, v in remapping.items()}
        if len(reverse) != len(remapping):
            logerr(f"SMACH userdata remapping is not one-to-one: {dict(remapping)}")
        out = UserData()
        for k in keys:
            out[reverse.get(k, k)] = copy.copy(self[k])
        return out

    def merge(self, ud: UserData, keys: Iterable[str], remapping: Mapping[str, str]) -> None:
        """Copy ``keys`` of ``ud`` in, renamed through ``remapping``."""
        for k in keys:
            self[remapping.get(k, k)] = copy.copy(ud[k])

    def keys(self) -> list[str]:
        with self._lock:
            return list(self._data)

    def __contains__(self, key: object) -> bool:
        return key in self._data

    def __getitem__(self, key: str) -> Any:
        with self._lock:
            if key in self._data:
                return self._data[key]
            available = list(self._data)
        logerr(f"Userdata key '{key}' not available. Available keys are: {available}")
        raise KeyError(key)

    def __setitem__(self, key: str, item: Any) -> None:
        with self._lock:
            self._data[key] = item

    def __getattr__(self, name: str) -> Any:
        if name.startswith("_"):
            raise AttributeError(name)
        return self[name]

    def __setattr__(self, name: str, value: Any) -> None:
        if name.startswith("_"):
            object.__setattr__(self, name, value)
        else:
            self[name] = value

    def __repr__(self) -> str:
        return f"UserData({self._data!r})"


def get_const(obj: Any) -> Any:
    """A read-only view of ``obj`` if it has an instance ``__dict__`` (user objects), else ``obj`` itself."""
    if hasattr(obj, "__dict__"):
        return Const(obj)
    return obj


class Const:
    """Read-only wrapper for values a state declared as input but not output: setting an attribute
    logs an error and raises TypeError, as smach does."""

    def __init__(self, obj: Any) -> None:
        logdebug(f"Making const '{obj}'")
        object.__setattr__(self, "_obj", obj)

    def __getattr__(self, name: str) -> Any:
        return get_const(getattr(self._obj, name))

    def __getitem__(self, name: Any) -> Any:
        return get_const(self._obj[name])

    def __setattr__(self, name: str, value: Any) -> None:
        logerr(f"Attempting to set '{name}' but this member is read-only.")
        raise TypeError(f"'{name}' is read-only: the key is an input, not an output, of this state")

    def __delattr__(self, name: str) -> None:
        logerr(f"Attempting to delete '{name}' but this member is read-only.")
        raise TypeError(f"'{name}' is read-only: the key is an input, not an output, of this state")

    def __eq__(self, other: object) -> bool:
        return bool(self._obj == (other._obj if isinstance(other, Const) else other))

    def __hash__(self) -> int:
        return hash(self._obj)

    def __len__(self) -> int:
        return len(self._obj)

    def __iter__(self) -> Any:
        return iter(self._obj)

    def __repr__(self) -> str:
        return repr(self._obj)


class Remapper:
    """One state's view of its container's userdata: declared keys only, names remapped."""

    def __init__(
        self,
        ud: Any,
        input_keys: Iterable[str] = (),
        output_keys: Iterable[str] = (),
        remapping: Mapping[str, str] | None = None,
    ) -> None:
        object.__setattr__(self, "_ud", ud)
        object.__setattr__(self, "_input", list(input_keys))
        object.__setattr__(self, "_output", list(output_keys))
        object.__setattr__(self, "_map", dict(remapping or {}))

    def _remap(self, key: str) -> str:
        return self._map.get(key, key)

    def _read(self, key: str) -> Any:
        if key not in self._input:
            raise InvalidUserCodeError(
                f"Reading from SMACH userdata key '{key}' but the only keys that were declared as input "
                f"to this state were: {self._input}. This key needs to be declared as input to this state. "
            )
        value = self._ud[self._remap(key)]
        return value if key in self._output else get_const(value)

    def _write(self, key: str, value: Any) -> None:
        if key not in self._output:
            logerr(
                f"Writing to SMACH userdata key '{key}' but the only keys that were declared as output "
                f"from this state were: {self._output}."
            )
            return
        self._ud[self._remap(key)] = value

    def update(self, other_userdata: Any) -> None:
        self._ud.update(other_userdata)

    def keys(self) -> list[str]:
        return [self._remap(k) for k in self._ud.keys() if k in self._input]

    def __contains__(self, key: object) -> bool:
        return key in self._input and self._remap(str(key)) in self._ud

    def __getitem__(self, key: str) -> Any:
        return self._read(key)

    def __setitem__(self, key: str, item: Any) -> None:
        self._write(key, item)

    def __getattr__(self, name: str) -> Any:
        if name.startswith("_"):
            raise AttributeError(name)
        return self._read(name)

    def __setattr__(self, name: str, value: Any) -> None:
        if name.startswith("_"):
            object.__setattr__(self, name, value)
        else:
            self._write(name, value)

"""The conversion table: message type name -> (to numpy, from numpy). Filled by the type modules,
which are imported the first time a conversion is asked for."""

from __future__ import annotations

import importlib
from collections.abc import Callable
from typing import Any

from ninjemys.errors import NinjemysError

_TO: dict[tuple[str, bool], Callable[..., Any]] = {}
_FROM: dict[tuple[str, bool], Callable[..., Any]] = {}
_MODULES = ("geometry", "image", "occupancy_grid", "point_cloud2")
_loaded = False


class ConversionError(NinjemysError, TypeError):
    """No conversion for this message type (TypeError, as ros_numpy raises)."""


def _type_name(cls: Any) -> str:
    return str(getattr(cls, "_type", cls))


def converts_to_numpy(
    msgtype: Any, plural: bool = False
) -> Callable[[Callable[..., Any]], Callable[..., Any]]:
    def register(fn: Callable[..., Any]) -> Callable[..., Any]:
        _TO[(_type_name(msgtype), plural)] = fn
        return fn

    return register


def converts_from_numpy(
    msgtype: Any, plural: bool = False
) -> Callable[[Callable[..., Any]], Callable[..., Any]]:
    def register(fn: Callable[..., Any]) -> Callable[..., Any]:
        _FROM[(_type_name(msgtype), plural)] = fn
        return fn

    return register


def _load() -> None:
    global _loaded
    if not _loaded:
        for name in _MODULES:
            importlib.import_module(f"ros_numpy.{name}")
        _loaded = True


def numpify(msg: Any, *args: Any, **kwargs: Any) -> Any:
    """The numpy form of ``msg`` (None stays None); a list of messages of one type converts as a plural."""
    if msg is None:
        return None
    _load()
    conv = _TO.get((_type_name(type(msg)), False))
    if conv is None and isinstance(msg, list | tuple) and msg:
        conv = _TO.get((_type_name(type(msg[0])), True))
    if conv is None:
        known = sorted(t for t, _ in _TO)
        raise ConversionError(f"Cannot convert type {type(msg).__name__} to numpy; known types: {known}")
    return conv(msg, *args, **kwargs)


def msgify(msg_type: Any, numpy_obj: Any, *args: Any, plural: bool = False, **kwargs: Any) -> Any:
    """A ``msg_type`` message (or list, ``plural=True``) built from ``numpy_obj``."""
    _load()
    conv = _FROM.get((_type_name(msg_type), plural))
    if conv is None:
        known = sorted(t for t, _ in _FROM)
        raise ConversionError(f"Cannot convert numpy to type {_type_name(msg_type)}; known types: {known}")
    return conv(numpy_obj, *args, **kwargs)

"""Build messages from command-line YAML, as ``rostopic pub`` and ``rosservice call`` do.

Each command-line argument is one YAML document. A single mapping fills fields by name
(``'{linear: {x: 0.2}}'``); otherwise the arguments fill the message's fields in order
(``rostopic pub /chatter std_msgs/String hello``). The strings ``now`` (for a time field) and
``auto`` (for a Header) are substituted with the current time, as in ROS 1.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from ninjemys.errors import NinjemysError
from ninjemys.idl.spec import BUILTIN_TYPES
from ninjemys.paramyaml import ParamYamlError, load_yaml


class MessageArgsError(NinjemysError):
    """Command-line values that do not fit the message's fields."""


def parse_yaml_args(args: list[str]) -> list[Any]:
    """One YAML value per argument; a mistake names the argument and the position in it."""
    values = []
    for index, text in enumerate(args):
        try:
            values.append(load_yaml(text))
        except ParamYamlError as exc:
            raise MessageArgsError(f"Invalid YAML in argument {index + 1} ({text!r}): {exc}") from None
    return values


def _split_type(slot_type: str) -> tuple[str, bool, int | None]:
    if "[" not in slot_type:
        return slot_type, False, None
    base, rest = slot_type.split("[", 1)
    size = rest.rstrip("]")
    return base, True, int(size) if size else None


def fill_message_args(msg: Any, args: list[Any], keys: Mapping[str, Any] | None = None) -> None:
    """Fill ``msg`` in place from YAML-parsed ``args`` (genpy.message.fill_message_args semantics)."""
    keys = keys or {}
    if len(args) == 1 and isinstance(args[0], dict):
        _fill(msg, args[0], keys, "")
    elif args:
        _fill(msg, list(args), keys, "")


def _fill(msg: Any, values: Any, keys: Mapping[str, Any], prefix: str) -> None:
    slots = list(msg.__slots__)
    if isinstance(values, dict):
        for name, value in values.items():
            _fill_field(msg, str(name), value, keys, prefix)
        return
    if not isinstance(values, list | tuple):
        values = [values]
    if len(values) > len(slots):
        raise MessageArgsError(
            f"Too many arguments for {msg._type}:\n * Given: {list(values)}\n * Expected: {slots}"
        )
    if len(values) < len(slots):
        raise MessageArgsError(
            f"Not enough arguments for {msg._type}:\n * Given: {list(values)}\n * Expected: {slots}"
        )
    for name, value in zip(slots, values, strict=True):
        _fill_field(msg, name, value, keys, prefix)


def _fill_field(msg: Any, name: str, value: Any, keys: Mapping[str, Any], prefix: str) -> None:
    from ninjemys.idl.loader import get_message_class
    from ninjemys.rostime import Duration, Time

    if name not in msg.__slots__:
        raise MessageArgsError(f"No field name [{prefix}{name}]")
    slot_type = msg._slot_types[msg.__slots__.index(name)]
    base, is_array, size = _split_type(slot_type)
    where = f"{prefix}{name}"
    if is_array:
        if not isinstance(value, list | tuple):
            if base in ("uint8", "char") and isinstance(value, bytes | str):
                setattr(msg, name, value.encode() if isinstance(value, str) else value)
                return
            raise MessageArgsError(
                f"Field [{where}] must be a list or tuple instead of: {type(value).__name__}"
            )
        if size is not None and len(value) != size:
            raise MessageArgsError(
                f"Field [{where}] has incorrect number of elements: {len(value)} != {size}"
            )
        if base in ("uint8", "char"):
            setattr(msg, name, bytes(value))
        elif base in BUILTIN_TYPES and base not in ("time", "duration"):
            setattr(msg, name, list(value))
        else:
            items = []
            for index, item in enumerate(value):
                items.append(_make_value(base, item, keys, f"{where}[{index}]."))
            setattr(msg, name, items)
        return
    if base in ("time", "duration"):
        setattr(msg, name, _time_value(Time if base == "time" else Duration, value, keys, where))
        return
    if base not in BUILTIN_TYPES:
        if isinstance(value, str):
            if value not in keys:
                raise MessageArgsError(f"No key named [{value}] for field [{where}]")
            setattr(msg, name, keys[value])
            return
        current = getattr(msg, name)
        if current is None:
            current = get_message_class(base)()
            setattr(msg, name, current)
        _fill(current, value, keys, where + ".")
        return
    setattr(msg, name, value)


def _make_value(base: str, item: Any, keys: Mapping[str, Any], prefix: str) -> Any:
    from ninjemys.idl.loader import get_message_class
    from ninjemys.rostime import Duration, Time

    if base in ("time", "duration"):
        return _time_value(Time if base == "time" else Duration, item, keys, prefix.rstrip("."))
    inner = get_message_class(base)()
    _fill(inner, item, keys, prefix)
    return inner


def _time_value(cls: Any, value: Any, keys: Mapping[str, Any], where: str) -> Any:
    if isinstance(value, str):
        if value in keys:
            return keys[value]
        raise MessageArgsError(f"No key named [{value}] for field [{where}]")
    if isinstance(value, int):
        return cls.from_sec(value / 1e9)
    if isinstance(value, dict):
        return cls(value.get("secs", 0), value.get("nsecs", 0))
    if isinstance(value, list | tuple) and len(value) == 2:
        return cls(*value)
    if isinstance(value, float):
        return cls.from_sec(value)
    raise MessageArgsError(f"Field [{where}] must be a time (secs/nsecs, nanoseconds or 'now')")


def substitution_keys(now: Any) -> dict[str, Any]:
    """``now`` -> the current time, ``auto`` -> a Header stamped now."""
    from ninjemys.idl.loader import get_message_class

    header = get_message_class("std_msgs/Header")(stamp=now)
    return {"now": now, "auto": header}

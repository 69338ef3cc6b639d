"""genpy.message: the Message base class, its exceptions, and the helpers ROS 1 programs use on
messages (filling one from YAML-parsed arguments, checking a field's type, printing it as YAML).

``Message`` is the base of every generated class of ours, so ``isinstance(m, genpy.Message)`` holds
at no cost. SerializationError and DeserializationError are the ones our messages raise; they are
MessageExceptions only by name here (see docs/parity.md): ``except genpy.MessageException`` does not
catch them, ``except genpy.SerializationError`` does.
"""

from __future__ import annotations

import struct
from collections.abc import Mapping
from typing import Any

from ninjemys.errors import DeserializationError, SerializationError
from ninjemys.idl.message import Message, strify_message
from ninjemys.idl.spec import PRIMITIVE_FORMATS
from roslib.message import get_message_class, get_service_class

from .base import is_simple
from .rostime import Duration, Time, TVal

__all__ = [
    "Message",
    "MessageException",
    "SerializationError",
    "DeserializationError",
    "struct_I",
    "strify_message",
    "check_type",
    "fill_message_args",
    "get_printable_message_args",
    "get_message_class",
    "get_service_class",
    "isstring",
    "is_simple",
]

struct_I = struct.Struct("<I")

_WIDTHS = {"byte": 8, "char": 8, "int8": 8, "uint8": 8, "int16": 16, "uint16": 16}
_WIDTHS.update({"int32": 32, "uint32": 32, "int64": 64, "uint64": 64})
_SIGNED = ("byte", "int8", "int16", "int32", "int64")
_UNSIGNED = ("char", "uint8", "uint16", "uint32", "uint64")
#: genmsg's PRIMITIVE_TYPES: numbers, bool and string (time and duration are builtin, not primitive)
_PRIMITIVE = frozenset(PRIMITIVE_FORMATS) | {"string"}


class MessageException(Exception):
    """A message cannot be built from the values given (genpy's base of message errors)."""


def isstring(s: object) -> bool:
    """True for str (ROS 1 keeps it for Python 2 compatibility)."""
    return isinstance(s, str)


def check_type(field_name: str, field_type: str, field_val: Any) -> None:
    """Raise SerializationError naming ``field_name`` if ``field_val`` does not fit ``field_type``
    (a slow diagnosis, recursing into nested messages and arrays, with ROS 1's texts)."""
    if field_type in _SIGNED or field_type in _UNSIGNED:
        if type(field_val) is not int or (field_type in _UNSIGNED and field_val < 0):
            kind = "an integer type" if field_type in _SIGNED else "unsigned integer type"
            raise SerializationError(f"field {field_name} must be {kind}")
        bits = _WIDTHS[field_type]
        low, high = (-(2 ** (bits - 1)), 2 ** (bits - 1)) if field_type in _SIGNED else (0, 2**bits)
        if not low <= field_val < high:
            raise SerializationError(f"field {field_name} exceeds specified width [{field_type}]")
    elif field_type in ("float32", "float64"):
        if type(field_val) not in (float, int):
            raise SerializationError(f"field {field_name} must be float type")
    elif field_type == "bool":
        if field_val not in (True, False, 0, 1):
            raise SerializationError(f"field {field_name} is not a bool")
    elif field_type == "string":
        if type(field_val) is str:
            if not field_val.isascii():
                raise SerializationError(f"field {field_name} is a non-ascii string")
        elif type(field_val) is not bytes:
            raise SerializationError(f"field {field_name} must be of type bytes or an ascii string")
    elif field_type in ("time", "duration"):
        cls = Time if field_type == "time" else Duration
        if not isinstance(field_val, cls):
            raise SerializationError(f"field {field_name} must be of type {cls.__name__}")
    elif field_type.endswith("]"):
        base_type = field_type[: field_type.index("[")]
        if type(field_val) in (bytes, str):
            if base_type not in ("char", "uint8"):
                raise SerializationError(
                    f"field {field_name} must be a list or tuple type. Only uint8[] can be a string"
                )
            return
        if type(field_val) not in (list, tuple):
            raise SerializationError(f"field {field_name} must be a list or tuple type")
        for v in field_val:
            check_type(field_name + "[]", base_type, v)
    elif isinstance(field_val, Message):
        if field_val._type in ("std_msgs/Header", "roslib/Header"):
            if field_type not in ("Header", "std_msgs/Header", "roslib/Header"):
                raise SerializationError(
                    f"field {field_name} must be a Header instead of a {field_val._type}"
                )
        elif field_val._type != field_type:
            raise SerializationError(
                f"field {field_name} must be of type {field_type} instead of {field_val._type}"
            )
        for n, t in zip(field_val.__slots__, field_val._get_types(), strict=True):
            check_type(f"{field_name}.{n}", t, getattr(field_val, n))
    else:
        raise SerializationError(f"field {field_name} must be of type [{field_type}]")


def get_printable_message_args(msg: Message, buff: Any = None, prefix: str = "") -> str:
    """The field names of ``msg`` as ``rostopic pub`` lists them, nested fields dotted."""
    names: list[str] = []
    for f in msg.__slots__:
        value = getattr(msg, f)
        if isinstance(value, Message):
            names.append(get_printable_message_args(value, prefix=prefix + f + "."))
        else:
            names.append(prefix + f)
    text = " ".join(n for n in names if n)
    if buff is not None:
        buff.write(text)
    return text


def _time_from_nsecs(cls: type, nsecs: int) -> TVal:
    return cls(nsecs // 1_000_000_000, nsecs % 1_000_000_000)


def _fill_val(msg: Any, f: str, v: Any, keys: Mapping[str, Any], prefix: str) -> None:
    if f not in msg.__slots__:
        raise MessageException(f"No field name [{prefix}{f}]")
    current = getattr(msg, f)
    if isinstance(current, Message | TVal):
        if type(v) is str:
            if v not in keys:
                raise MessageException(f"No key named [{v}]")
            setattr(msg, f, keys[v])
        elif isinstance(current, TVal) and type(v) is int:
            setattr(msg, f, _time_from_nsecs(type(current), v))
        else:
            _fill_message_args(current, v, keys, prefix + f + ".")
        return
    slot_type = msg._slot_types[msg.__slots__.index(f)]
    if "[" not in slot_type:
        setattr(msg, f, v)
        return
    if type(v) not in (list, tuple):
        raise MessageException(f"Field [{prefix}{f}] must be a list or tuple instead of: {type(v).__name__}")
    base_type, size = slot_type.split("[", 1)
    if size != "]" and len(v) != int(size[:-1]):
        raise MessageException(
            f"Field [{prefix}{f}] has incorrect number of elements: {len(v)} != {size[:-1]}"
        )
    if base_type in _PRIMITIVE:
        setattr(msg, f, v)
        return
    if base_type in ("time", "duration"):
        cls: Any = Time if base_type == "time" else Duration
    else:
        cls = get_message_class(base_type)
        if cls is None:
            raise MessageException(
                f"Cannot instantiate messages for field [{prefix}{f}] : cannot load class {base_type}"
            )
    items = []
    for el in v:
        inner = cls()
        if isinstance(inner, TVal) and type(el) is int:
            inner = _time_from_nsecs(cls, el)
        else:
            _fill_message_args(inner, el, keys, prefix)
        items.append(inner)
    setattr(msg, f, items)


def _fill_message_args(msg: Any, msg_args: Any, keys: Mapping[str, Any], prefix: str = "") -> None:
    if not isinstance(msg, Message | TVal):
        raise ValueError(f"msg must be a Message instance: {msg}")
    if type(msg_args) is dict:
        for f, v in msg_args.items():
            _fill_val(msg, f, "" if v is None else v, keys, prefix)
    elif type(msg_args) is list:
        slots = list(msg.__slots__)
        if len(msg_args) != len(slots):
            what = "Too many" if len(msg_args) > len(slots) else "Not enough"
            raise MessageException(f"{what} arguments:\n * Given: {msg_args}\n * Expected: {slots}")
        for f, v in zip(slots, msg_args, strict=True):
            _fill_val(msg, f, v, keys, prefix)
    else:
        raise ValueError(f"invalid msg_args type: {msg_args}")


def fill_message_args(msg: Any, msg_args: list[Any] | None, keys: Mapping[str, Any] = {}) -> None:  # noqa: B006  (ROS 1's default, never mutated)
    """Fill ``msg`` in place from YAML-parsed command-line ``msg_args`` (one list per field in order,
    or one dict of fields); ``keys`` maps strings such as ``"now"`` to Time/Message values."""
    if msg_args is None:
        msg_args = []
    if len(msg_args) == 1 and type(msg_args[0]) is dict:
        _fill_message_args(msg, msg_args[0], keys, "")
    else:
        _fill_message_args(msg, msg_args, keys, "")

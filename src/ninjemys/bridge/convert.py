"""Messages <-> rosbridge's JSON/CBOR values, as rosbridge_library's ``message_conversion`` defines them.

To JSON: time and duration become ``{"secs", "nsecs"}``, ``uint8[]``/``char[]`` (fixed or variable)
become a base64 string, other arrays lists, nested messages objects, NaN and infinities ``null``
(and ``null`` in a float field reads back as NaN). To CBOR: the same, except that
``uint8[]`` is a byte string and numeric arrays are RFC 8746 typed arrays (a tag over little-endian
bytes), as rosbridge's ``cbor_conversion``. From JSON: fields missing from the object keep their
defaults, unknown fields and values of the wrong type are refused with one line naming the type,
the field and what was expected.

One converter per (class, mode) is built once from the class's ``_slot_types`` and cached.
"""

from __future__ import annotations

import base64
import math
from collections.abc import Callable
from typing import Any

import cbor2
import numpy

from ninjemys.errors import NinjemysError
from ninjemys.idl.loader import get_message_class
from ninjemys.idl.message import Message
from ninjemys.rostime import Duration, Time

_INTS = {"byte", "char", "int8", "uint8", "int16", "uint16", "int32", "uint32", "int64", "uint64"}
_FLOATS = {"float32", "float64"}
_BYTES = {"uint8", "char"}
#: RFC 8746 tags for little-endian typed arrays (rosbridge's cbor_conversion uses the same)
_CBOR_TAGS = {
    "uint8": 64,
    "char": 64,
    "byte": 72,
    "int8": 72,
    "uint16": 69,
    "uint32": 70,
    "uint64": 71,
    "int16": 77,
    "int32": 78,
    "int64": 79,
    "float32": 85,
    "float64": 86,
}
_NUMPY_DTYPES = {
    "byte": "<i1",
    "int8": "<i1",
    "uint16": "<u2",
    "uint32": "<u4",
    "uint64": "<u8",
    "int16": "<i2",
    "int32": "<i4",
    "int64": "<i8",
    "float32": "<f4",
    "float64": "<f8",
}
_INT_RANGES = {
    "byte": (-128, 127),
    "int8": (-128, 127),
    "char": (0, 255),
    "uint8": (0, 255),
    "int16": (-(2**15), 2**15 - 1),
    "uint16": (0, 2**16 - 1),
    "int32": (-(2**31), 2**31 - 1),
    "uint32": (0, 2**32 - 1),
    "int64": (-(2**63), 2**63 - 1),
    "uint64": (0, 2**64 - 1),
}


class ConversionError(NinjemysError, ValueError):
    """A JSON value does not fit the message field it was given for (the text names both)."""


def _split(slot_type: str) -> tuple[str, bool, int | None]:
    """``'float64[9]'`` -> ``('float64', True, 9)``; ``'string'`` -> ``('string', False, None)``."""
    if slot_type.endswith("]"):
        base, _, size = slot_type[:-1].partition("[")
        return base, True, int(size) if size else None
    return slot_type, False, None


# -- to JSON / CBOR ---------------------------------------------------------------------------------

_encoders: dict[tuple[type, bool], Callable[[Any], dict]] = {}


def to_value(msg: Any, cbor: bool = False) -> dict:
    """``msg`` as rosbridge's JSON object (``cbor=True``: the CBOR flavour, bytes and typed arrays)."""
    cls = type(msg)
    encoder = _encoders.get((cls, cbor))
    if encoder is None:
        encoder = _encoders[(cls, cbor)] = _build_encoder(cls, cbor)
    return encoder(msg)


def _finite(x: float) -> float | None:
    """NaN and infinities as null: JSON has no spelling for them (a browser's JSON.parse rejects
    Python's ``NaN``); CBOR keeps them."""
    return x if x - x == 0 else None


def _time_value(t: Any) -> dict:
    return {"secs": t.secs, "nsecs": t.nsecs}


def _field_encoder(slot_type: str, cbor: bool) -> Callable[[Any], Any] | None:
    """How one field's value becomes JSON; None where the value is already JSON (numbers, str, bool)."""
    base, is_array, _size = _split(slot_type)
    if not is_array:
        if base in ("time", "duration"):
            return _time_value
        if base in _FLOATS and not cbor:
            return _finite
        if base == "string" or base == "bool" or base in _INTS or base in _FLOATS:
            return None
        return lambda v: to_value(v, cbor)
    if base in _BYTES:
        if cbor:
            return bytes
        return lambda v: base64.b64encode(
            v if isinstance(v, bytes | bytearray | memoryview) else bytes(v)
        ).decode("ascii")
    if cbor and base in _NUMPY_DTYPES:
        tag, dtype = _CBOR_TAGS[base], _NUMPY_DTYPES[base]
        return lambda v: cbor2.CBORTag(tag, numpy.asarray(v, dtype=dtype).tobytes())
    if base == "bool":
        return lambda v: [bool(x) for x in v]
    if base in _FLOATS and not cbor:
        return lambda v: [x if x - x == 0 else None for x in v]
    if base in _INTS or base in _FLOATS or base == "string":
        return list
    if base in ("time", "duration"):
        return lambda v: [_time_value(x) for x in v]
    return lambda v: [to_value(x, cbor) for x in v]


def _build_encoder(cls: type[Message], cbor: bool) -> Callable[[Any], dict]:
    fields = [(name, _field_encoder(t, cbor)) for name, t in zip(cls.__slots__, cls._slot_types, strict=True)]

    def encode(msg: Any) -> dict:
        out = {}
        for name, conv in fields:
            value = getattr(msg, name)
            out[name] = value if conv is None else conv(value)
        return out

    return encode


# -- from JSON ------------------------------------------------------------------------------------


def from_value(cls: type[Message], value: Any, where: str = "") -> Any:
    """A ``cls`` instance from rosbridge's JSON object (``where`` prefixes error texts: the field path)."""
    if value is None:
        value = {}
    if not isinstance(value, dict):
        raise ConversionError(
            f"{where or cls._type}: expected a JSON object for type {cls._type}, got {_json_type(value)}"
        )
    msg = cls()
    slots = dict(zip(cls.__slots__, cls._slot_types, strict=True))
    for name, item in value.items():
        slot_type = slots.get(name)
        if slot_type is None:
            raise ConversionError(f"message type {cls._type} has no field {name!r}")
        setattr(msg, name, _field_value(slot_type, item, f"{where or cls._type}.{name}"))
    return msg


def _json_type(value: Any) -> str:
    return {dict: "object", list: "array", str: "string", bool: "bool", type(None): "null"}.get(
        type(value), type(value).__name__
    )


def _scalar(base: str, item: Any, where: str) -> Any:
    if base == "string":
        if isinstance(item, str):
            return item
        raise ConversionError(f"{where}: expected a string, got {_json_type(item)}")
    if base == "bool":
        if isinstance(item, bool):
            return item
        if isinstance(item, int) and item in (0, 1):
            return bool(item)
        raise ConversionError(f"{where}: expected a bool, got {_json_type(item)}")
    if base in _INTS:
        if isinstance(item, int) and not isinstance(item, bool):
            lo, hi = _INT_RANGES[base]
            if not lo <= item <= hi:
                raise ConversionError(f"{where}: {item} is out of range for {base}")
            return item
        raise ConversionError(f"{where}: expected an integer ({base}), got {_json_type(item)}")
    if base in _FLOATS:
        if isinstance(item, int | float) and not isinstance(item, bool):
            return float(item)
        if item is None:  # rosbridge clients send null for NaN (JSON has no NaN)
            return math.nan
        raise ConversionError(f"{where}: expected a number ({base}), got {_json_type(item)}")
    if base in ("time", "duration"):
        cls = Time if base == "time" else Duration
        if isinstance(item, dict):
            secs, nsecs = item.get("secs", 0), item.get("nsecs", 0)
            if isinstance(secs, int) and isinstance(nsecs, int):
                return cls(secs, nsecs)
        if isinstance(item, int | float) and not isinstance(item, bool):
            return cls.from_sec(float(item))
        raise ConversionError(f"{where}: expected {{secs, nsecs}} for a {base}, got {_json_type(item)}")
    return from_value(get_message_class(base), item, where)


def _field_value(slot_type: str, item: Any, where: str) -> Any:
    base, is_array, size = _split(slot_type)
    if not is_array:
        return _scalar(base, item, where)
    if base in _BYTES:
        if isinstance(item, str):
            try:
                data = base64.b64decode(item, validate=True)
            except ValueError:
                raise ConversionError(f"{where}: expected base64 text for {slot_type}") from None
        elif isinstance(item, bytes | bytearray):
            data = bytes(item)
        elif isinstance(item, list):
            data = bytes(_scalar(base, x, f"{where}[{i}]") for i, x in enumerate(item))
        else:
            raise ConversionError(f"{where}: expected base64 text or an array, got {_json_type(item)}")
        if size is not None and len(data) != size:
            raise ConversionError(f"{where}: expected {size} bytes, got {len(data)}")
        return data
    if not isinstance(item, list):
        raise ConversionError(f"{where}: expected an array for {slot_type}, got {_json_type(item)}")
    if size is not None and len(item) != size:
        raise ConversionError(f"{where}: expected {size} elements, got {len(item)}")
    return [_scalar(base, x, f"{where}[{i}]") for i, x in enumerate(item)]

"""genpy.base: the fixed-size ("simple") field types and their struct format characters."""

from __future__ import annotations

from ninjemys.idl.spec import PRIMITIVE_FORMATS

_ORDER = (
    "int8",
    "uint8",
    "bool",
    "int16",
    "uint16",
    "int32",
    "uint32",
    "int64",
    "uint64",
    "float32",
    "float64",
)
#: type -> struct format character, as genpy generates code from it (genpy's order; char and byte,
#: deprecated, last)
SIMPLE_TYPES_DICT: dict[str, str] = {name: PRIMITIVE_FORMATS[name][0] for name in (*_ORDER, "char", "byte")}
SIMPLE_TYPES = list(SIMPLE_TYPES_DICT)


def is_simple(type_: str) -> bool:
    """True for a type of fixed serialized size: every primitive but string."""
    return type_ in SIMPLE_TYPES_DICT

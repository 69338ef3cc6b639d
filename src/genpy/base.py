"""genpy.base: the fixed-size ("simple") field types and their struct format characters."""

from __future__ import annotations

from ninjemys.idl.spec import PRIMITIVE_FORMATS

#: type -> struct format character, as genpy generates code from it
SIMPLE_TYPES_DICT: dict[str, str] = {name: fmt for name, (fmt, _size) in PRIMITIVE_FORMATS.items()}
SIMPLE_TYPES = list(SIMPLE_TYPES_DICT)


def is_simple(type_: str) -> bool:
    """True for a type of fixed serialized size: every primitive but string."""
    return type_ in SIMPLE_TYPES_DICT

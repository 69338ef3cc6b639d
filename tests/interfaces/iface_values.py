"""Random message values as JSON-able trees, and the bridge between trees and our message classes.

A tree is the interchange form shared with the genpy oracle (see genpy_oracle_server.py): a message is a
dict keyed by field name, ``uint8[]``/``char[]`` are ``{"$b": base64}``, ``time``/``duration`` are
``{"$t": [secs, nsecs]}``/``{"$d": [secs, nsecs]}``, other arrays are lists. Strategies are derived from our
classes' ``__slots__``/``_slot_types``; if those are wrong, genpy rejects the tree and the test fails.
"""

from __future__ import annotations

import base64
import functools
from typing import Any

from hypothesis import strategies as st

from ninjemys.idl.loader import get_message_class
from ninjemys.rostime import Duration, Time

INT_RANGES: dict[str, tuple[int, int]] = {
    "int8": (-(2**7), 2**7 - 1),
    "byte": (-(2**7), 2**7 - 1),
    "uint8": (0, 2**8 - 1),
    "char": (0, 2**8 - 1),
    "int16": (-(2**15), 2**15 - 1),
    "uint16": (0, 2**16 - 1),
    "int32": (-(2**31), 2**31 - 1),
    "uint32": (0, 2**32 - 1),
    "int64": (-(2**63), 2**63 - 1),
    "uint64": (0, 2**64 - 1),
}
BYTES_TYPES = ("uint8", "char")
NSECS = st.integers(0, 999_999_999)
#: keep nested arrays short: visualization_msgs nests message arrays four levels deep
MESSAGE_ARRAY_MAX = 2
PRIMITIVE_ARRAY_MAX = 6


def split_slot_type(slot_type: str) -> tuple[str, bool, int | None]:
    """``"float64[36]"`` -> ("float64", True, 36); ``"Point[]"`` -> ("Point", True, None)."""
    if not slot_type.endswith("]"):
        return slot_type, False, None
    base, _, rest = slot_type.partition("[")
    length = rest[:-1]
    return base, True, int(length) if length else None


def resolve(base: str) -> str:
    return "std_msgs/Header" if base == "Header" else base


def _scalar_strategy(base: str) -> st.SearchStrategy[Any] | None:
    if base in INT_RANGES:
        lo, hi = INT_RANGES[base]
        return st.integers(lo, hi)
    match base:
        case "bool":
            return st.booleans()
        case "float32":
            return st.floats(width=32, allow_nan=False)
        case "float64":
            return st.floats(allow_nan=False)
        case "string":
            return st.text(max_size=6)
        case "time":
            return st.builds(lambda s, n: {"$t": [s, n]}, st.integers(0, 2**32 - 1), NSECS)
        case "duration":
            return st.builds(lambda s, n: {"$d": [s, n]}, st.integers(-(2**31), 2**31 - 1), NSECS)
    return None


def _b64(data: bytes) -> dict[str, str]:
    return {"$b": base64.b64encode(data).decode("ascii")}


def slot_strategy(slot_type: str) -> st.SearchStrategy[Any]:
    base, is_array, length = split_slot_type(slot_type)
    if is_array and base in BYTES_TYPES:
        size = {"min_size": length, "max_size": length} if length is not None else {"max_size": 16}
        return st.binary(**size).map(_b64)
    element = _scalar_strategy(base)
    is_message = element is None
    if is_message:
        element = st.deferred(lambda: tree_strategy(resolve(base)))
    if not is_array:
        return element
    if length is not None:
        return st.lists(element, min_size=length, max_size=length)
    return st.lists(element, max_size=MESSAGE_ARRAY_MAX if is_message else PRIMITIVE_ARRAY_MAX)


@functools.cache
def tree_strategy(type_name: str) -> st.SearchStrategy[dict[str, Any]]:
    cls = get_message_class(type_name)
    return st.fixed_dictionaries(
        {
            name: slot_strategy(slot_type)
            for name, slot_type in zip(cls.__slots__, cls._slot_types, strict=True)
        }
    )


def build_ours(type_name: str, tree: dict[str, Any]) -> Any:
    """Tree -> instance of our generated class (keyword constructor, as user code does it)."""
    cls = get_message_class(type_name)
    kwargs = {
        name: _build_value(slot_type, tree[name])
        for name, slot_type in zip(cls.__slots__, cls._slot_types, strict=True)
    }
    return cls(**kwargs)


def _build_value(slot_type: str, value: Any) -> Any:
    base, is_array, _ = split_slot_type(slot_type)
    if is_array and base in BYTES_TYPES:
        return base64.b64decode(value["$b"])
    if is_array:
        return [_build_value(base, v) for v in value]
    if base == "time":
        return Time(*value["$t"])
    if base == "duration":
        return Duration(*value["$d"])
    if isinstance(value, dict):
        return build_ours(resolve(base), value)
    return value


def tree_of_ours(msg: Any) -> dict[str, Any]:
    """Instance of our class -> tree, accepting every container the contract allows (bytes, numpy, lists)."""
    return {
        name: _tree_value(slot_type, getattr(msg, name))
        for name, slot_type in zip(msg.__slots__, msg._slot_types, strict=True)
    }


def _tree_value(slot_type: str, value: Any) -> Any:
    base, is_array, _ = split_slot_type(slot_type)
    if is_array and base in BYTES_TYPES:
        return _b64(bytes(value))
    if is_array:
        items = value.tolist() if hasattr(value, "tolist") else list(value)
        return [_tree_value(base, v) for v in items]
    if base == "time":
        return {"$t": [value.secs, value.nsecs]}
    if base == "duration":
        return {"$d": [value.secs, value.nsecs]}
    if _scalar_strategy(base) is not None:
        return value.item() if hasattr(value, "item") else value
    return tree_of_ours(value)

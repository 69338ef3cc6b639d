"""The YAML prototype of a message or service request, as ``rosmsg-proto`` prints it for completion.

``rostopic pub /chatter std_msgs/String <Tab>`` inserts ``"data: ''"``: a default instance as
double-quoted YAML, ready to edit. The layout follows ROS 1's: fields in declaration order, empty
variable-length arrays get one default element (``position: [0]``) so the user sees the element's
shape, block style until a message with more than four fields or an array with more than four
items has been met, from then on PyYAML's compromise (flow style for collections of scalars, so
``stamp: {secs: 0, nsecs: 0}`` inside a five-field message). One deliberate difference: byte
arrays (``uint8[]``) show as ``[]`` instead of ROS 1's ``!!binary ""``, which rostopic pub can parse.
"""

from __future__ import annotations

from typing import Any

import yaml

#: ROS 1 keeps block style for messages of at most this many fields
_MAX_BLOCK_ITEMS = 4
_INTEGER_TYPES = frozenset(
    {"byte", "char", "int8", "uint8", "int16", "uint16", "int32", "uint32", "int64", "uint64"}
)


class _Fields:
    """An ordered mapping of one message's fields, with the style decision it triggers."""

    __slots__ = ("items", "switches_style")

    def __init__(self, items: list[tuple[str, Any]], switches_style: bool) -> None:
        self.items = items
        self.switches_style = switches_style


class _ProtoDumper(yaml.SafeDumper):
    """A SafeDumper whose flow style flips from block to PyYAML's heuristic once a large message or
    array has been met, the way ROS 1's representer mutates its dumper while walking a message."""


def _represent_fields(dumper: _ProtoDumper, fields: _Fields) -> yaml.Node:
    if fields.switches_style:
        dumper.default_flow_style = None  # type: ignore[assignment]  # PyYAML's heuristic; typeshed says bool
    return dumper.represent_mapping("tag:yaml.org,2002:map", fields.items)


_ProtoDumper.add_representer(_Fields, _represent_fields)


def _element_default(slot_type: str, package: str) -> Any:
    """One default element of an array field (ROS 1 fills floats with the integer 0 too)."""
    base = slot_type.partition("[")[0]
    if base in _INTEGER_TYPES or base in ("float32", "float64"):
        return 0
    if base == "string":
        return ""
    if base == "bool":
        return False
    from ninjemys.idl.loader import get_message_class

    match base:
        case "time":
            base = "std_msgs/Time"
        case "duration":
            base = "std_msgs/Duration"
        case "Header":
            base = "std_msgs/Header"
        case _ if "/" not in base:
            base = f"{package}/{base}"
    return _convert(get_message_class(base)())


def _convert(value: Any) -> Any:
    """A message instance (or field value) as plain data for the dumper."""
    slots = getattr(value, "__slots__", None)
    slot_types = getattr(value, "_slot_types", None)
    if slots is not None and slot_types is not None:
        package = str(getattr(value, "_type", "")).partition("/")[0]
        items: list[tuple[str, Any]] = []
        switches = len(slots) > _MAX_BLOCK_ITEMS
        for name, slot_type in zip(slots, slot_types, strict=True):
            field = getattr(value, name)
            if isinstance(field, (bytes, bytearray)):
                items.append((name, list(field)))
                continue
            if isinstance(field, (list, tuple)):
                switches = switches or len(field) > _MAX_BLOCK_ITEMS
                if not field and slot_type.endswith("[]"):
                    items.append((name, [_element_default(slot_type, package)]))
                    continue
            items.append((name, _convert(field)))
        return _Fields(items, switches)
    if hasattr(value, "secs") and hasattr(value, "nsecs"):  # time / duration
        return _Fields([("secs", value.secs), ("nsecs", value.nsecs)], False)
    if isinstance(value, (list, tuple)):
        return [_convert(v) for v in value]
    if hasattr(value, "tolist"):  # a numpy array or scalar
        return _convert(value.tolist())
    return value


def prototype(instance: Any) -> str:
    """``"<yaml>"``: the instance as rosmsg-proto prints it (quoted, no trailing newline)."""
    text = yaml.dump(
        _convert(instance),
        Dumper=_ProtoDumper,
        default_flow_style=False,
        sort_keys=False,
        allow_unicode=True,
    )
    return '"' + text.rstrip("\n") + '"'


def message_prototype(type_name: str) -> str:
    """The prototype of message type ``pkg/Type`` (TypeNotFoundError if it is unknown)."""
    from ninjemys.idl.loader import get_message_class

    return prototype(get_message_class(type_name)())


def request_prototype(type_name: str) -> str:
    """The prototype of the request of service type ``pkg/Type``."""
    from ninjemys.idl.loader import get_service_class

    return prototype(get_service_class(type_name)._request_class())

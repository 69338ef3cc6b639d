"""The genpy oracle: Debian's real ROS 1 message classes, answering JSON-line requests on stdin.

Runs under /usr/bin/python3 (never the project venv) and imports nothing from ninjemys. One process
serves a whole test session, so the per-request cost is a pipe round trip, not an interpreter start.

Request: one JSON object per line, ``{"op": ..., ...}``; answer: one JSON object per line, either
``{"ok": result}`` or ``{"error": "text"}``.

Value trees (the JSON form of a message): a message is an object keyed by field name; ``uint8[]`` and
``char[]`` values are ``{"$b": base64}``; ``time`` / ``duration`` are ``{"$t": [secs, nsecs]}`` /
``{"$d": [secs, nsecs]}``; every other array is a JSON list; bools are JSON booleans.
"""

from __future__ import annotations

import base64
import io
import json
import sys
import traceback

import genpy
import genpy.dynamic
import roslib.message

_classes: dict[str, type] = {}


def _real_class(type_name: str) -> type | None:
    """The class Debian ships for a message type, or for a service's Request/Response part."""
    cls = roslib.message.get_message_class(type_name)
    if cls is not None:
        return cls
    for part, attr in (("Request", "_request_class"), ("Response", "_response_class")):
        if type_name.endswith(part):
            srv = roslib.message.get_service_class(type_name[: -len(part)])
            if srv is not None:
                return getattr(srv, attr)
    return None


def message_class(type_name: str) -> type:
    cls = _classes.get(type_name)
    if cls is None:
        cls = _real_class(type_name)
        if cls is None:
            raise KeyError(f"no genpy class for {type_name} (send a 'define' first)")
        _classes[type_name] = cls
    return cls


def _base(slot_type: str) -> tuple[str, bool]:
    if "[" in slot_type:
        return slot_type[: slot_type.index("[")], True
    return slot_type, False


def _resolve(base: str) -> str:
    return "std_msgs/Header" if base == "Header" else base


_BYTES_TYPES = ("uint8", "char")
_SCALARS = {
    "bool",
    "int8",
    "uint8",
    "byte",
    "char",
    "int16",
    "uint16",
    "int32",
    "uint32",
    "int64",
    "uint64",
    "float32",
    "float64",
    "string",
}


def build(type_name: str, tree: dict):
    """Value tree -> genpy message instance."""
    cls = message_class(type_name)
    kwargs = {}
    for name, slot_type in zip(cls.__slots__, cls._slot_types, strict=True):
        kwargs[name] = _build_value(slot_type, tree[name])
    return cls(**kwargs)


def _build_value(slot_type: str, value):
    base, is_array = _base(slot_type)
    if is_array and base in _BYTES_TYPES:
        return base64.b64decode(value["$b"])
    if is_array:
        return [_build_value(base, v) for v in value]
    if base == "time":
        return genpy.Time(*value["$t"])
    if base == "duration":
        return genpy.Duration(*value["$d"])
    if base in _SCALARS:
        return value
    return build(_resolve(base), value)


def tree_of(msg) -> dict:
    """genpy message instance -> value tree."""
    out = {}
    for name, slot_type in zip(msg.__slots__, msg._slot_types, strict=True):
        out[name] = _tree_value(slot_type, getattr(msg, name))
    return out


def _tree_value(slot_type: str, value):
    base, is_array = _base(slot_type)
    if is_array and base in _BYTES_TYPES:
        return {"$b": base64.b64encode(bytes(value)).decode("ascii")}
    if is_array:
        return [_tree_value(base, v) for v in value]
    if base == "time":
        return {"$t": [value.secs, value.nsecs]}
    if base == "duration":
        return {"$d": [value.secs, value.nsecs]}
    if base in _SCALARS:
        return value
    return tree_of(value)


def _describe(cls) -> dict:
    constants = {
        k: getattr(cls, k)
        for k in dir(cls)
        if not k.startswith("_") and k not in cls.__slots__ and not callable(getattr(cls, k))
    }
    return {
        "md5": cls._md5sum,
        "slots": list(cls.__slots__),
        "slot_types": list(cls._slot_types),
        "constants": constants,
        "has_header": bool(cls._has_header),
        # the embedded types of the full text, in ROS 1's order
        "embedded": [line[5:] for line in cls._full_text.split("\n") if line.startswith("MSG: ")],
    }


def op_describe(req: dict) -> dict:
    """md5, fields and constants of Debian's class for each type (null where Debian lacks it)."""
    out = {}
    for name in req["types"]:
        cls = _real_class(name)
        out[name] = None if cls is None else _describe(cls)
    return out


def op_srv_md5(req: dict) -> dict:
    out = {}
    for name in req["types"]:
        srv = roslib.message.get_service_class(name)
        out[name] = None if srv is None else srv._md5sum
    return out


def op_decode_full_text(req: dict) -> dict:
    """Generate a class from a message_definition as a ROS 1 subscriber would (genpy.dynamic)."""
    generated = genpy.dynamic.generate_dynamic(req["type"], req["full_text"])
    return _describe(generated[req["type"]])


def op_define(req: dict) -> str:
    """Make a type known: Debian's real class when it has one, else generated from our full text."""
    name = req["type"]
    if _real_class(name) is not None:
        message_class(name)
        return "debian"
    generated = genpy.dynamic.generate_dynamic(name, req["full_text"])
    for type_name, cls in generated.items():
        _classes.setdefault(type_name, cls)
    _classes[name] = generated[name]
    return "dynamic"


def op_serialize(req: dict) -> list[str]:
    out = []
    for tree in req["values"]:
        buff = io.BytesIO()
        build(req["type"], tree).serialize(buff)
        out.append(base64.b64encode(buff.getvalue()).decode("ascii"))
    return out


def op_deserialize(req: dict) -> list[dict]:
    cls = message_class(req["type"])
    return [tree_of(cls().deserialize(base64.b64decode(data))) for data in req["data"]]


def op_strify(req: dict) -> list[str]:
    """``str(msg)``: the YAML that rostopic echo prints."""
    return [str(build(req["type"], tree)) for tree in req["values"]]


def op_defaults(req: dict) -> dict:
    """Bytes and YAML of a default-constructed instance of each type (the ROS defaults)."""
    out = {}
    for name in req["types"]:
        msg = message_class(name)()
        buff = io.BytesIO()
        msg.serialize(buff)
        out[name] = {"data": base64.b64encode(buff.getvalue()).decode("ascii"), "text": str(msg)}
    return out


OPS = {
    "defaults": op_defaults,
    "strify": op_strify,
    "describe": op_describe,
    "srv_md5": op_srv_md5,
    "decode_full_text": op_decode_full_text,
    "define": op_define,
    "serialize": op_serialize,
    "deserialize": op_deserialize,
}


def main() -> None:
    for line in sys.stdin:
        try:
            req = json.loads(line)
            answer = {"ok": OPS[req["op"]](req)}
        except Exception as exc:  # report every failure to the test, never die mid-session
            answer = {"error": f"{type(exc).__name__}: {exc}\n{traceback.format_exc()}"}
        sys.stdout.write(json.dumps(answer) + "\n")
        sys.stdout.flush()


if __name__ == "__main__":
    main()

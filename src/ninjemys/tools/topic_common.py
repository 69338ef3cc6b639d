"""What rostopic's subcommands share: name resolution, waiting for a topic's type, loading the
message class (from the publisher's definition for types we do not ship), field paths and filters."""

from __future__ import annotations

import math
import sys
import time
from collections.abc import Callable
from typing import Any

from ninjemys import names
from ninjemys.errors import NinjemysError, TypeNotFoundError

NAME = "rostopic"
ID = "/rostopic"
#: How long ``echo`` lets messages gather before its thread wakes (seconds): on a VM one wake-up
#: costs more CPU than printing a small message, and a person reading the output cannot tell 10 ms.
#: (hz/bw/delay time each arrival, so they take every message as it comes.)
COALESCE = 0.01


class TopicToolError(NinjemysError):
    """A rostopic usage or lookup error."""


def resolve_topic(name: str) -> str:
    """A topic name as typed, resolved in ROS_NAMESPACE (rostopic's script_resolve_name)."""
    return names.resolve_name(name, names.get_ros_namespace() + NAME)


def topic_type(client: Any, topic: str) -> tuple[str | None, str | None, str | None]:
    """(type, real topic, field path) for ``/topic`` or ``/topic/field/sub`` (longest topic prefix)."""
    types = dict(client.get_topic_types())
    if topic in types:
        return types[topic], topic, None
    candidates = [t for t in types if topic.startswith(t + "/")]
    if not candidates:
        return None, None, None
    real = max(candidates, key=len)
    return types[real], real, topic[len(real) + 1 :]


def make_node(name: str = "rostopic") -> Any:
    from ninjemys.node import Node

    return Node(name, anonymous=True)


def wait_for_type(client: Any, topic: str, announce: bool = True) -> tuple[str, str, str | None]:
    """Block until the topic (or a topic owning this field path) has a known type, as ROS 1 does."""
    ttype, real, field = topic_type(client, topic)
    if ttype is not None:
        return ttype, real, field  # type: ignore[return-value]
    if announce:
        sys.stderr.write(f"WARNING: topic [{topic}] does not appear to be published yet\n")
    while True:
        time.sleep(0.1)
        ttype, real, field = topic_type(client, topic)
        if ttype is not None:
            return ttype, real, field  # type: ignore[return-value]


def class_for(ttype: str, header: Any) -> Any:
    from ninjemys.idl.loader import get_message_class, message_class_from_definition

    try:
        return get_message_class(ttype)
    except TypeNotFoundError:
        definition = header.get("message_definition") if header else None
        if not definition:
            raise TopicToolError(
                f"Cannot load message class for [{ttype}]. Are your messages built?"
            ) from None
        return message_class_from_definition(ttype, definition, header.get("md5sum"))


def field_getter(path: str | None) -> Callable[[Any], Any] | None:
    """``/field/sub[0]`` or ``field/arr[1:3]`` -> a function extracting it from a message."""
    if not path:
        return None
    steps: list[tuple[str, slice | int | None]] = []
    for part in (p for p in path.split("/") if p):
        index: slice | int | None = None
        if "[" in part:
            name, rest = part.split("[", 1)
            if not rest.endswith("]"):
                raise TopicToolError(f"missing closing ']' in slice spec '{part}'")
            spec = rest[:-1]
            try:
                if ":" in spec:
                    bounds = [int(x) if x else None for x in spec.split(":")]
                    index = slice(*bounds)
                else:
                    index = int(spec)
            except ValueError:
                raise TopicToolError(f"field '{name}' has invalid slice argument '{spec}'") from None
        else:
            name = part
        steps.append((name, index))

    def get(msg: Any) -> Any:
        value = msg
        for name, index in steps:
            if name:
                try:
                    value = getattr(value, name)
                except AttributeError:
                    raise TopicToolError(f"no field named {name} in {path}") from None
            if index is not None:
                value = value[index]
        return value

    return get


def compile_filter(expr: str | None) -> Callable[[Any, str], bool] | None:
    if not expr:
        return None
    try:
        code = compile(expr, "<--filter>", "eval")
    except SyntaxError as exc:
        raise TopicToolError(f"invalid --filter expression {expr!r}: {exc.msg}") from None

    def predicate(msg: Any, topic: str) -> bool:
        return bool(eval(code, {"m": msg, "topic": topic, "math": math}))  # noqa: S307 - the user's own expression

    return predicate

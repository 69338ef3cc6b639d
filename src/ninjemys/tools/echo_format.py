"""How ``rostopic echo`` (and ``rosbag``/``rosservice`` printers) render messages.

The YAML-ish form comes from :func:`ninjemys.idl.message.strify_message` (genpy's format); this
module adds rostopic's options: ``---`` separators, ``-p`` CSV, ``-c`` screen clearing, ``--noarr``,
``--nostr`` and ``--offset``.
"""

from __future__ import annotations

from collections.abc import Iterator
from typing import Any

from ninjemys.idl.message import Message, strify_message

CLEAR = "\033[2J\033[;H"


def field_filter(noarr: bool, nostr: bool) -> Any:
    """rostopic's filter: drop array fields (--noarr) and string fields (--nostr)."""
    if not (noarr or nostr):
        return None

    def keep(msg: Message) -> Iterator[str]:
        for name, slot_type in zip(msg.__slots__, msg._slot_types, strict=True):
            if noarr and "[" in slot_type:
                continue
            if nostr and "string" in slot_type:
                continue
            yield name

    return keep


class EchoPrinter:
    """Turns one echoed value into the text rostopic echo writes for it."""

    def __init__(
        self,
        plot: bool = False,
        clear: bool = False,
        noarr: bool = False,
        nostr: bool = False,
        offset: bool = False,
        width: int | None = None,
    ) -> None:
        self.plot = plot
        self.prefix = CLEAR if clear and not plot else ""
        self.filter = field_filter(noarr, nostr)
        self.offset = offset
        self.width = width
        self._first = True

    def render(self, value: Any) -> str:
        if self.plot:
            return self._render_plot(value)
        offset = None
        if self.offset:
            from ninjemys.rostime import Time

            offset = Time.now()
        if isinstance(value, bytes | bytearray | memoryview):
            # a uint8[] field echoed alone (`rostopic echo /t/data`): numbers, as rostopic means to
            # print it (ros_comm #243; Noetic's Python 3 rostopic stops there on ord() of an int)
            value = list(value)
        body = strify_message(value, time_offset=offset, field_filter=self.filter)
        return f"{self.prefix}{body}\n---\n"

    # -- -p: comma-separated values, one header line of field names ------------------------------
    def _render_plot(self, value: Any) -> str:
        from ninjemys.rostime import Time

        out = ""
        if self._first:
            names = ",".join(name for name, _ in _flatten(value, "field", self.filter))
            out = f"%time,{names}\n" if names else "%time\n"
            self._first = False
        stamp = value.header.stamp if getattr(value, "_has_header", False) else Time.now()
        values = ",".join(_plot_text(v) for _, v in _flatten(value, "field", self.filter))
        return out + f"{stamp.to_nsec()}" + (f",{values}" if values else "") + "\n"


def _flatten(value: Any, prefix: str, keep: Any) -> Iterator[tuple[str, Any]]:
    from ninjemys.rostime import TVal

    if isinstance(value, Message):
        names = set(keep(value)) if keep is not None else None
        for name in value.__slots__:
            if names is not None and name not in names:
                continue
            yield from _flatten(getattr(value, name), f"{prefix}.{name}", keep)
    elif isinstance(value, TVal):
        yield prefix, value.to_nsec()
    elif isinstance(value, list | tuple) and value and isinstance(value[0], Message):
        for index, item in enumerate(value):
            yield from _flatten(item, f"{prefix}{index}", keep)
    elif isinstance(value, bytes | bytearray | memoryview):
        for index, item in enumerate(bytes(value)):
            yield f"{prefix}{index}", item
    elif isinstance(value, list | tuple) or (hasattr(value, "tolist") and not isinstance(value, str)):
        for index, item in enumerate(value.tolist() if hasattr(value, "tolist") else value):
            yield f"{prefix}{index}", item
    else:
        yield prefix, value


def _plot_text(value: Any) -> str:
    if isinstance(value, str):
        return value
    return str(value)

"""A minimal XML tree with line numbers (expat), so every launch error can say ``file:line``."""

from __future__ import annotations

import xml.parsers.expat
from dataclasses import dataclass, field

from ninjemys.errors import LaunchError


@dataclass
class Element:
    tag: str
    attrs: dict[str, str]
    line: int
    children: list[Element] = field(default_factory=list)
    text: str = ""

    def has(self, name: str) -> bool:
        return name in self.attrs

    def to_xml(self) -> str:
        """A short rendering for error messages (the start tag only)."""
        attrs = "".join(f' {k}="{v}"' for k, v in self.attrs.items())
        return f"<{self.tag}{attrs}>"


def parse_xml(data: bytes | str, filename: str) -> Element:
    """Parse launch XML; malformed input raises LaunchError ``filename:line: ...``."""
    parser = xml.parsers.expat.ParserCreate()
    root_holder: list[Element] = []
    stack: list[Element] = []

    def start(tag: str, attrs: dict[str, str]) -> None:
        el = Element(tag, dict(attrs), parser.CurrentLineNumber)
        if stack:
            stack[-1].children.append(el)
        else:
            root_holder.append(el)
        stack.append(el)

    def end(tag: str) -> None:
        stack.pop()

    def chars(data: str) -> None:
        if stack:
            stack[-1].text += data

    parser.StartElementHandler = start
    parser.EndElementHandler = end
    parser.CharacterDataHandler = chars
    parser.ordered_attributes = False
    try:
        parser.Parse(data.encode("utf-8") if isinstance(data, str) else data, True)
    except xml.parsers.expat.ExpatError as exc:
        raise LaunchError(
            f"{filename}:{exc.lineno}: Invalid roslaunch XML syntax: {xml.parsers.expat.ErrorString(exc.code)}"
        ) from None
    if not root_holder or root_holder[0].tag != "launch":
        raise LaunchError(f"{filename}:1: Invalid roslaunch XML syntax: no root <launch> tag")
    return root_holder[0]

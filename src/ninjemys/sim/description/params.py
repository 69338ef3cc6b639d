"""Typed reading of a Gazebo plugin's or sensor's child elements, with Gazebo's defaults.

Gazebo reads ``<wheelSeparation>0.2</wheelSeparation>`` with SDF's parser: a value that does not parse
is an error there too, but one buried in gzserver's log. Here it is a DescriptionError naming the file,
line, element path and reason, and a missing element takes the plugin's default.
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from typing import TypeVar

from ninjemys.sim.description.xmltree import Document

T = TypeVar("T")
_TRUE = ("true", "1")
_FALSE = ("false", "0")


class Reader:
    """Child values of one element (a ``<plugin>`` or ``<sensor>``), with a label for errors."""

    def __init__(self, doc: Document, el: ET.Element, label: str) -> None:
        self.doc, self.el, self.label = doc, el, label

    def _child(self, path: str) -> ET.Element | None:
        return self.el.find(path)

    def has(self, path: str) -> bool:
        return self._child(path) is not None

    def _fail(self, child: ET.Element, path: str, reason: str) -> Exception:
        return self.doc.error(child, f"{self.label}: {reason}", path)

    def text(self, path: str, default: str) -> str:
        child = self._child(path)
        if child is None:
            return default
        return (child.text or "").strip()

    def number(
        self, path: str, default: float, *, minimum: float | None = None, positive: bool = False
    ) -> float:
        child = self._child(path)
        if child is None:
            return default
        raw = (child.text or "").strip()
        try:
            value = float(raw)
        except ValueError:
            raise self._fail(child, path, f"'{raw}' is not a number") from None
        if not math.isfinite(value):
            raise self._fail(child, path, f"'{raw}' is not a finite number")
        if positive and value <= 0:
            raise self._fail(child, path, f"must be > 0, got {raw}")
        if minimum is not None and value < minimum:
            raise self._fail(child, path, f"must be >= {minimum:g}, got {raw}")
        return value

    def integer(self, path: str, default: int, *, positive: bool = False) -> int:
        child = self._child(path)
        if child is None:
            return default
        raw = (child.text or "").strip()
        try:
            value = int(raw)
        except ValueError:
            raise self._fail(child, path, f"'{raw}' is not an integer") from None
        if positive and value <= 0:
            raise self._fail(child, path, f"must be > 0, got {raw}")
        return value

    def boolean(self, path: str, default: bool) -> bool:
        child = self._child(path)
        if child is None:
            return default
        raw = (child.text or "").strip().lower()
        if raw in _TRUE:
            return True
        if raw in _FALSE:
            return False
        raise self._fail(child, path, f"'{child.text}' is not a boolean (true/false/1/0)")

    def choice(self, path: str, default: str, options: tuple[str, ...]) -> str:
        value = self.text(path, default)
        if value not in options:
            child = self._child(path)
            assert child is not None
            raise self._fail(child, path, f"'{value}' is not one of {', '.join(options)}")
        return value

    def vector(self, path: str, n: int, default: tuple[float, ...]) -> tuple[float, ...]:
        child = self._child(path)
        if child is None:
            return default
        raw = (child.text or "").strip()
        try:
            values = tuple(float(v) for v in raw.split())
        except ValueError:
            values = ()
        if len(values) != n or not all(math.isfinite(v) for v in values):
            raise self._fail(child, path, f"'{raw}' is not {n} finite numbers")
        return values

"""``rosparam get``/``dump`` output without importing PyYAML: the text ``yaml.dump(value)`` prints.

Why: importing PyYAML is ~25 ms, as much as the rest of ``rosparam get`` together. Printing is the
common case and needs only a small emitter; parsing (``set``/``load``) still uses PyYAML.

What it must match, byte for byte, is ROS 1's ``rosparam``: PyYAML's block style (``yaml.dump`` with
sorted keys, 80-column folding, ``allow_unicode=False`` so non-ASCII text is ``\\x``/``\\u``-escaped in
double quotes) and rosparam's extra implicit resolvers, which make strings like ``deg(90)`` print
quoted. The walk below mirrors the decisions PyYAML's emitter makes for the value types a parameter
server holds (dict with string keys, list, str, int, float, bool, None): which scalar style, where a
long line folds, how collections nest and indent, and when the ``...`` document end is written.

:func:`dump` returns ``None`` for anything it cannot promise to print identically (``bytes``, other
types, non-string or awkward mapping keys that PyYAML would print as ``? key``, one object reached
twice, which PyYAML prints with anchors); the caller then uses PyYAML. tests/tools/test_paramyaml_emit.py
checks it against PyYAML on random parameter trees.
"""

from __future__ import annotations

import re

#: characters YAML treats as line breaks and as whitespace (for indicator and folding decisions)
_BREAKS = "\n\x85\u2028\u2029"
_WHITESPACE = "\0 \t\r\n\x85\u2028\u2029"
#: a leading character that makes a plain scalar impossible
_LEADING_INDICATORS = "#,[]{}&*!|>'\"%@`"
#: folding column of PyYAML's emitter
_WIDTH = 80
_INDENT_STEP = 2
#: PyYAML writes a mapping key as ``? key`` from this length on (we then defer to PyYAML)
_MAX_SIMPLE_KEY = 128

_ESCAPES = {
    "\0": "0",
    "\x07": "a",
    "\x08": "b",
    "\t": "t",
    "\n": "n",
    "\x0b": "v",
    "\x0c": "f",
    "\r": "r",
    "\x1b": "e",
    '"': '"',
    "\\": "\\",
    "\x85": "N",
    "\xa0": "_",
    "\u2028": "L",
    "\u2029": "P",
}

STR, INT, FLOAT, BOOL, NULL, OTHER = "str", "int", "float", "bool", "null", "other"

#: YAML 1.1 implicit types as PyYAML resolves plain scalars, in PyYAML's order, plus rosparam's
#: ``deg(...)``/``rad(...)`` angles (ROS 1 registers them on the dumper too): (first characters,
#: required prefix, type, pattern). A string that would read back as another type must be quoted.
#: Word lists stand for patterns that are a list of words; patterns are compiled on first use (most
#: texts are ruled out by their first character).
_RESOLVERS: list[tuple[str, str, str, str | frozenset[str]]] = [
    (
        "yYnNtTfFoO",
        "",
        BOOL,
        frozenset("yes Yes YES no No NO true True TRUE false False FALSE on On ON off Off OFF".split()),
    ),
    (
        "-+0123456789.",
        "",
        FLOAT,
        r"^(?:[-+]?(?:[0-9][0-9_]*)\.[0-9_]*(?:[eE][-+][0-9]+)?"
        r"|\.[0-9][0-9_]*(?:[eE][-+][0-9]+)?"
        r"|[-+]?[0-9][0-9_]*(?::[0-5]?[0-9])+\.[0-9_]*"
        r"|[-+]?\.(?:inf|Inf|INF)"
        r"|\.(?:nan|NaN|NAN))$",
    ),
    (
        "-+0123456789",
        "",
        INT,
        r"^(?:[-+]?0b[0-1_]+|[-+]?0[0-7_]+|[-+]?(?:0|[1-9][0-9_]*)"
        r"|[-+]?0x[0-9a-fA-F_]+|[-+]?[1-9][0-9_]*(?::[0-5]?[0-9])+)$",
    ),
    ("<", "<<", OTHER, frozenset(["<<"])),
    ("~nN", "", NULL, frozenset(["~", "null", "Null", "NULL"])),
    (
        "0123456789",
        "",
        OTHER,
        r"^(?:[0-9]{4}-[0-9]{2}-[0-9]{2}"
        r"|[0-9]{4}-[0-9]{1,2}-[0-9]{1,2}(?:[Tt]|[ \t]+)[0-9]{1,2}:[0-9]{2}:[0-9]{2}(?:\.[0-9]*)?"
        r"(?:[ \t]*(?:Z|[-+][0-9]{1,2}(?::[0-9]{2})?))?)$",
    ),
    ("=", "=", OTHER, frozenset(["="])),
    ("!&*", "", OTHER, frozenset(["!", "&", "*"])),
    ("deg(", "deg(", OTHER, r"^deg\([^\)]*\)$"),
    ("rad(", "rad(", OTHER, r"^rad\([^\)]*\)$"),
]
_compiled: dict[str, re.Pattern[str]] = {}


class _Unsupported(Exception):
    """Raised inside the walk when PyYAML's output for this value is not one we reproduce."""


#: every character the number and timestamp patterns accept (exponents, 0b, .inf/.nan, T/Z of times)
_NUMERIC_CHARS = frozenset("0123456789_.:+- \teEbinfINFaAtTZ")
#: those patterns (float, int, timestamp), by source: skipped (never compiled) for text with other characters
_NUMERIC_SOURCES = frozenset(
    source for firsts, _, kind, source in _RESOLVERS if kind in (FLOAT, INT) or firsts == "0123456789"
)


def _numeric_like(text: str) -> bool:
    """False when no number or timestamp pattern can match (none has two dots: '1.15.15' is text)."""
    if text.lstrip("+-").startswith("0x"):
        return True
    return text.count(".") < 2 and all(ch in _NUMERIC_CHARS for ch in text)


def implicit_type(text: str) -> str:
    """The type a plain (unquoted) YAML scalar ``text`` reads back as: ``str``, ``int``, ``float``, ..."""
    if not text:
        return NULL
    first = text[0]
    numeric: bool | None = None
    for firsts, prefix, kind, source in _RESOLVERS:
        if first not in firsts or not text.startswith(prefix):
            continue
        if not isinstance(source, str):
            # a pattern's '$' also matches before a final line break: 'yes\n' resolves like 'yes'
            if text in source or (text[-1] == "\n" and text[:-1] in source):
                return kind
            continue
        if source in _NUMERIC_SOURCES:
            if numeric is None:
                numeric = _numeric_like(text)
            if not numeric:
                continue
        pattern = _compiled.get(source)
        if pattern is None:
            pattern = _compiled[source] = re.compile(source)
        if pattern.match(text):
            return kind
    return STR


def _word_like(text: str) -> bool:
    """ASCII letters, digits and ``_`` only: no indicator, space, break or escape can be involved."""
    return text.isascii() and text.replace("_", "a").isalnum()


class _Analysis:
    """Which scalar styles can carry a text unchanged (the part of PyYAML's analysis we need)."""

    __slots__ = ("empty", "multiline", "plain", "single_quoted")

    def __init__(self, text: str) -> None:
        self.empty = not text
        self.multiline = False
        self.plain = True
        self.single_quoted = True
        if not text or _word_like(text):
            return
        n = len(text)
        indicators = text.startswith(("---", "..."))
        special = breaks = break_space = space_break = False
        for i, ch in enumerate(text):
            followed_by_ws = i + 1 >= n or text[i + 1] in _WHITESPACE
            if i == 0:
                if ch in _LEADING_INDICATORS or (ch in "?:-" and followed_by_ws):
                    indicators = True
            elif (ch == ":" and followed_by_ws) or (ch == "#" and text[i - 1] in _WHITESPACE):
                indicators = True
            if ch in _BREAKS:
                breaks = True
                if i and text[i - 1] == " ":
                    space_break = True
            elif ch == " " and i and text[i - 1] in _BREAKS:
                break_space = True
            if ch != "\n" and not " " <= ch <= "~":
                special = True  # control characters, and any non-ASCII (ROS 1 dumps with allow_unicode off)
        edges = text[0] in " " + _BREAKS or text[-1] in " " + _BREAKS
        self.multiline = breaks
        self.single_quoted = not (break_space or space_break or special)
        self.plain = self.single_quoted and not (edges or breaks or indicators)


class _Emitter:
    """Writes one YAML document the way PyYAML's emitter does, for parameter-server values."""

    def __init__(self) -> None:
        self.out: list[str] = []
        self.column = 0
        self.whitespace = True  # the last character written is whitespace
        self.indention = True  # only indentation (and '-', '?', ':') on the current line so far
        self.indent: int | None = None
        self.open_ended = False  # a root plain scalar needs the '...' document end
        self._containers: set[int] = set()

    # ---------------------------------------------------------------------------------- writing

    def _write(self, data: str) -> None:
        self.column += len(data)
        self.out.append(data)

    def _indicator(
        self, text: str, need_space: bool, whitespace: bool = False, indention: bool = False
    ) -> None:
        self._write(text if self.whitespace or not need_space else " " + text)
        self.whitespace = whitespace
        self.indention = self.indention and indention
        self.open_ended = False

    def _line_break(self) -> None:
        self.out.append("\n")
        self.whitespace = self.indention = True
        self.column = 0

    def _to_indent(self) -> None:
        indent = self.indent or 0
        if not self.indention or self.column > indent or (self.column == indent and not self.whitespace):
            self._line_break()
        if self.column < indent:
            self.whitespace = True
            self._write(" " * (indent - self.column))

    # ------------------------------------------------------------------------------------ nodes

    def document(self, value: object) -> str:
        self._node(value, root=True)
        self._to_indent()
        if self.open_ended:
            self._indicator("...", True)
            self._to_indent()
        return "".join(self.out)

    def _node(self, value: object, root: bool = False, in_mapping: bool = False) -> None:
        kind = type(value)
        if kind is str:
            self._scalar(value, STR, root, simple_key=False)  # type: ignore[arg-type]
        elif kind is bool:
            self._scalar("true" if value else "false", BOOL, root, simple_key=False)
        elif kind is int:
            self._scalar(str(value), INT, root, simple_key=False)
        elif kind is float:
            self._scalar(_float_text(value), FLOAT, root, simple_key=False)  # type: ignore[arg-type]
        elif value is None:
            self._scalar("null", NULL, root, simple_key=False)
        elif kind is dict or kind is list:
            if id(value) in self._containers:
                raise _Unsupported("one object reached twice (PyYAML writes an anchor)")
            self._containers.add(id(value))
            if not value:
                self._indicator("{" if kind is dict else "[", True, whitespace=True)
                self._indicator("}" if kind is dict else "]", False)
            elif kind is dict:
                self._mapping(value)  # type: ignore[arg-type]
            else:
                self._sequence(value, indentless=in_mapping and not self.indention)  # type: ignore[arg-type]
        else:
            raise _Unsupported(f"values of type {kind.__name__}")

    def _sequence(self, items: list[object], indentless: bool) -> None:
        saved = self.indent
        if self.indent is None:
            self.indent = 0
        elif not indentless:
            self.indent += _INDENT_STEP
        for item in items:
            self._to_indent()
            self._indicator("-", True, indention=True)
            self._node(item)
        self.indent = saved

    def _mapping(self, mapping: dict[object, object]) -> None:
        if any(type(key) is not str for key in mapping):
            raise _Unsupported("mapping keys that are not strings")
        saved = self.indent
        self.indent = 0 if self.indent is None else self.indent + _INDENT_STEP
        for key in sorted(mapping):  # type: ignore[type-var]
            self._to_indent()
            self._scalar(key, STR, root=False, simple_key=True)  # type: ignore[arg-type]
            self._indicator(":", False)
            self._node(mapping[key], in_mapping=True)
        self.indent = saved

    def _scalar(self, text: str, kind: str, root: bool, simple_key: bool) -> None:
        analysis = _Analysis(text)
        if simple_key and (len(text) >= _MAX_SIMPLE_KEY or analysis.empty or analysis.multiline):
            raise _Unsupported("a mapping key PyYAML writes as '? key'")
        # int/float/bool/null texts come from the representations above, which always read back as
        # their own type (tests/tools/test_paramyaml_emit.py checks); only strings need resolving
        reads_back = kind != STR or implicit_type(text) == STR
        if reads_back and analysis.plain and not (simple_key and analysis.empty):
            style = ""
        elif kind != STR:
            raise _Unsupported(f"a {kind} that needs an explicit tag")
        elif analysis.single_quoted:
            style = "'"
        else:
            style = '"'
        saved = self.indent
        self.indent = _INDENT_STEP if self.indent is None else self.indent + _INDENT_STEP
        fold = not simple_key
        if style == "":
            if root:
                self.open_ended = True
            self._plain(text, fold)
        elif style == "'":
            self._single_quoted(text, fold)
        else:
            self._double_quoted(text, fold)
        self.indent = saved

    # ---------------------------------------------------------------------------------- scalars

    def _plain(self, text: str, fold: bool) -> None:
        """Words as they are; a single space past column 80 becomes a line break (plain text here
        never holds line breaks: those strings are quoted)."""
        if not self.whitespace:
            self._write(" ")
        self.whitespace = self.indention = False
        if " " not in text:
            self._write(text)
            return
        for i, run in enumerate(re.split("( +)", text)):
            if i % 2 and len(run) == 1 and self.column > _WIDTH and fold:
                self._to_indent()
                self.whitespace = self.indention = False
            else:
                self._write(run)

    def _single_quoted(self, text: str, fold: bool) -> None:
        """Quotes doubled; a single inner space past column 80 folds; each line break is written
        twice-plus-one (YAML folds one break into a space when reading)."""
        self._indicator("'", True)
        n = len(text)
        global _single_runs
        if _single_runs is None:
            _single_runs = re.compile(_SINGLE_RUNS)
        for match in _single_runs.finditer(text):
            run = match.group()
            start, end = match.span()
            if run[0] == " ":
                if end - start == 1 and self.column > _WIDTH and fold and start != 0 and end != n:
                    self._to_indent()
                else:
                    self._write(run)
            elif run[0] in _BREAKS:
                if run[0] == "\n":
                    self._line_break()
                for _ in run:
                    self._line_break()
                self._to_indent()
            elif run == "'":
                self._write("''")
            else:
                self._write(run)
        self._indicator("'", False)

    def _double_quoted(self, text: str, fold: bool) -> None:
        """Escapes for everything outside printable ASCII; folds past column 80 with a trailing
        backslash (and a leading one when the next line starts with a space)."""
        self._indicator('"', True)
        n = len(text)
        start = end = 0
        while end <= n:
            ch = text[end] if end < n else None
            if ch is None or ch in '"\\' or not " " <= ch <= "~":
                if start < end:
                    self._write(text[start:end])
                    start = end
                if ch is not None:
                    self._write("\\" + _escape(ch))
                    start = end + 1
            if (
                fold
                and 0 < end < n - 1
                and (ch == " " or start >= end)
                and self.column + (end - start) > _WIDTH
            ):
                self._write(text[start:end] + "\\")
                start = max(start, end)
                self._to_indent()
                self.whitespace = self.indention = False
                if text[start] == " ":
                    self._write("\\")
            end += 1
        self._indicator('"', False)


#: runs the single-quoted writer treats as units: spaces, line breaks, a quote, anything else
_SINGLE_RUNS = "( +|[\n\x85\u2028\u2029]+|'|[^ \n\x85\u2028\u2029']+)"
_single_runs: re.Pattern[str] | None = None


def _escape(ch: str) -> str:
    named = _ESCAPES.get(ch)
    if named is not None:
        return named
    code = ord(ch)
    if code <= 0xFF:
        return f"x{code:02X}"
    if code <= 0xFFFF:
        return f"u{code:04X}"
    return f"U{code:08X}"


def _float_text(value: float) -> str:
    if value != value:
        return ".nan"
    if value in (float("inf"), float("-inf")):
        return ".inf" if value > 0 else "-.inf"
    text = repr(value).lower()
    if "." not in text and "e" in text:
        text = text.replace("e", ".0e", 1)  # 1e+17 is not a YAML 1.1 float; 1.0e+17 is
    return text


def dump(value: object) -> str | None:
    """``yaml.dump(value)`` as ROS 1's rosparam prints it, or ``None`` if only PyYAML can say."""
    try:
        return _Emitter().document(value)
    except (_Unsupported, RecursionError):
        return None


__all__ = ["dump", "implicit_type"]

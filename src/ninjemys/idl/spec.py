"""The typed intermediate representation of ROS 1 interface definitions.

The parser produces these plain, frozen records; md5, full-text and code generation consume them.
Type names inside a spec are always fully resolved: a bare ``Header`` is ``std_msgs/Header`` and a
same-package ``Point`` inside geometry_msgs is ``geometry_msgs/Point``. Builtin types keep the spelling
of the source (``byte`` and ``char`` stay as written, because the md5 text uses them verbatim).
"""

from __future__ import annotations

#: primitive type -> (struct format char, size in bytes). ``byte`` is int8 and ``char`` is uint8 (ROS 1).
PRIMITIVE_FORMATS: dict[str, tuple[str, int]] = {
    "bool": ("B", 1),
    "int8": ("b", 1),
    "uint8": ("B", 1),
    "byte": ("b", 1),
    "char": ("B", 1),
    "int16": ("h", 2),
    "uint16": ("H", 2),
    "int32": ("i", 4),
    "uint32": ("I", 4),
    "int64": ("q", 8),
    "uint64": ("Q", 8),
    "float32": ("f", 4),
    "float64": ("d", 8),
}
#: builtin = primitive numbers + string + time + duration (everything that is not a nested message)
BUILTIN_TYPES: frozenset[str] = frozenset(PRIMITIVE_FORMATS) | {"string", "time", "duration"}
HEADER_TYPE = "std_msgs/Header"
_set = object.__setattr__


class _Record:
    """Immutable, compared and hashed by value: what ``@dataclass(frozen=True, slots=True)`` gave these
    classes, written out because every node imports this module and the decorator (slots rebuild the
    class) cost several milliseconds of each start-up."""

    __slots__ = ()
    _fields: tuple[str, ...] = ()

    def _values(self) -> tuple[object, ...]:
        return tuple([getattr(self, name) for name in self._fields])

    def __eq__(self, other: object) -> bool:
        if other.__class__ is self.__class__:
            return self._values() == other._values()
        return NotImplemented

    def __hash__(self) -> int:
        return hash(self._values())

    def __repr__(self) -> str:
        inner = ", ".join(f"{name}={getattr(self, name)!r}" for name in self._fields)
        return f"{type(self).__name__}({inner})"

    def __setattr__(self, name: str, value: object) -> None:
        raise AttributeError(f"{type(self).__name__} is immutable: cannot assign to {name!r}")

    def __delattr__(self, name: str) -> None:
        raise AttributeError(f"{type(self).__name__} is immutable: cannot delete {name!r}")

    def __reduce__(self) -> tuple[object, ...]:
        return (type(self), self._values())


class _Named(_Record):
    """A record named ``pkg/Type`` (a message, service or action type): its package and short name."""

    __slots__ = ()
    full_name: str

    @property
    def package(self) -> str:
        return self.full_name.split("/", 1)[0]

    @property
    def short_name(self) -> str:
        return self.full_name.split("/", 1)[1]


class FieldType(_Record):
    """A field's type: ``base`` is a builtin name or a resolved ``pkg/Type``; arrays carry their length."""

    __slots__ = ("base", "is_array", "array_len")
    _fields = __slots__
    base: str
    is_array: bool
    array_len: int | None  # None for variable-length arrays (and for non-arrays)

    def __init__(self, base: str, is_array: bool = False, array_len: int | None = None) -> None:
        _set(self, "base", base)
        _set(self, "is_array", is_array)
        _set(self, "array_len", array_len)

    @property
    def is_builtin(self) -> bool:
        return self.base in BUILTIN_TYPES

    @property
    def is_primitive(self) -> bool:
        """A fixed-size number (the types that map to one struct format char)."""
        return self.base in PRIMITIVE_FORMATS

    @property
    def is_message(self) -> bool:
        return self.base not in BUILTIN_TYPES

    def __str__(self) -> str:
        if not self.is_array:
            return self.base
        return f"{self.base}[{'' if self.array_len is None else self.array_len}]"


class Field(_Record):
    __slots__ = ("name", "type", "raw_type")
    _fields = __slots__
    name: str
    type: FieldType
    #: the type exactly as written in the source (``Header``, ``Point[]``, ``byte``), for display
    raw_type: str

    def __init__(self, name: str, type: FieldType, raw_type: str) -> None:  # noqa: A002
        _set(self, "name", name)
        _set(self, "type", type)
        _set(self, "raw_type", raw_type)


class Constant(_Record):
    __slots__ = ("type", "name", "value", "value_text")
    _fields = __slots__
    type: str  # a primitive or ``string``
    name: str
    value: bool | int | float | str
    #: the value text as written after ``=`` (stripped, comments removed except for string constants)
    value_text: str

    def __init__(self, type: str, name: str, value: bool | int | float | str, value_text: str) -> None:  # noqa: A002
        _set(self, "type", type)
        _set(self, "name", name)
        _set(self, "value", value)
        _set(self, "value_text", value_text)


class MsgSpec(_Named):
    """One message type."""

    __slots__ = ("full_name", "fields", "constants", "text", "path")
    _fields = __slots__
    full_name: str  # "pkg/Type"
    fields: tuple[Field, ...]
    constants: tuple[Constant, ...]
    #: the definition text as it appears in the source file (comments kept): used for the full text
    text: str
    #: where it came from, for error messages (None for generated or in-memory definitions)
    path: str | None

    def __init__(
        self,
        full_name: str,
        fields: tuple[Field, ...] = (),
        constants: tuple[Constant, ...] = (),
        text: str = "",
        path: str | None = None,
    ) -> None:
        _set(self, "full_name", full_name)
        _set(self, "fields", fields)
        _set(self, "constants", constants)
        _set(self, "text", text)
        _set(self, "path", path)

    @property
    def has_header(self) -> bool:
        """ROS 1 rule: the first field is ``Header header`` (std_msgs/Header)."""
        return (
            bool(self.fields)
            and self.fields[0].type == FieldType(HEADER_TYPE)
            and self.fields[0].name == "header"
        )

    @property
    def dependencies(self) -> tuple[str, ...]:
        """Directly used message types, in field order, without duplicates."""
        seen: dict[str, None] = {}
        for f in self.fields:
            if f.type.is_message:
                seen.setdefault(f.type.base, None)
        return tuple(seen)


class SrvSpec(_Named):
    """A service: request and response are ordinary message specs named ``pkg/TypeRequest`` / ``...Response``."""

    __slots__ = ("full_name", "request", "response", "text", "path")
    _fields = __slots__
    full_name: str
    request: MsgSpec
    response: MsgSpec
    text: str
    path: str | None

    def __init__(
        self, full_name: str, request: MsgSpec, response: MsgSpec, text: str = "", path: str | None = None
    ) -> None:
        _set(self, "full_name", full_name)
        _set(self, "request", request)
        _set(self, "response", response)
        _set(self, "text", text)
        _set(self, "path", path)


class ActionSpec(_Named):
    """An action (.action: goal --- result --- feedback) and the 7 messages actionlib generates from it."""

    __slots__ = ("full_name", "goal", "result", "feedback", "generated", "text", "path")
    _fields = __slots__
    full_name: str
    goal: MsgSpec
    result: MsgSpec
    feedback: MsgSpec
    #: FooAction, FooActionGoal, FooActionResult, FooActionFeedback, FooGoal, FooResult, FooFeedback
    generated: tuple[MsgSpec, ...]
    text: str
    path: str | None

    def __init__(
        self,
        full_name: str,
        goal: MsgSpec,
        result: MsgSpec,
        feedback: MsgSpec,
        generated: tuple[MsgSpec, ...] = (),
        text: str = "",
        path: str | None = None,
    ) -> None:
        _set(self, "full_name", full_name)
        _set(self, "goal", goal)
        _set(self, "result", result)
        _set(self, "feedback", feedback)
        _set(self, "generated", generated)
        _set(self, "text", text)
        _set(self, "path", path)

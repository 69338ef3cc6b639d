"""The typed intermediate representation of ROS 1 interface definitions.

The parser produces these plain, frozen dataclasses; md5, full-text and code generation consume them.
Type names inside a spec are always fully resolved: a bare ``Header`` is ``std_msgs/Header`` and a
same-package ``Point`` inside geometry_msgs is ``geometry_msgs/Point``. Builtin types keep the spelling
of the source (``byte`` and ``char`` stay as written, because the md5 text uses them verbatim).
"""

from __future__ import annotations

from dataclasses import dataclass, field

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


@dataclass(frozen=True, slots=True)
class FieldType:
    """A field's type: ``base`` is a builtin name or a resolved ``pkg/Type``; arrays carry their length."""

    base: str
    is_array: bool = False
    array_len: int | None = None  # None for variable-length arrays (and for non-arrays)

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


@dataclass(frozen=True, slots=True)
class Field:
    name: str
    type: FieldType
    #: the type exactly as written in the source (``Header``, ``Point[]``, ``byte``), for display
    raw_type: str


@dataclass(frozen=True, slots=True)
class Constant:
    type: str  # a primitive or ``string``
    name: str
    value: bool | int | float | str
    #: the value text as written after ``=`` (stripped, comments removed except for string constants)
    value_text: str


@dataclass(frozen=True, slots=True)
class MsgSpec:
    """One message type."""

    full_name: str  # "pkg/Type"
    fields: tuple[Field, ...] = ()
    constants: tuple[Constant, ...] = ()
    #: the definition text as it appears in the source file (comments kept): used for the full text
    text: str = ""
    #: where it came from, for error messages (None for generated or in-memory definitions)
    path: str | None = None

    @property
    def package(self) -> str:
        return self.full_name.split("/", 1)[0]

    @property
    def short_name(self) -> str:
        return self.full_name.split("/", 1)[1]

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


@dataclass(frozen=True, slots=True)
class SrvSpec:
    """A service: request and response are ordinary message specs named ``pkg/TypeRequest`` / ``...Response``."""

    full_name: str
    request: MsgSpec
    response: MsgSpec
    text: str = ""
    path: str | None = None

    @property
    def package(self) -> str:
        return self.full_name.split("/", 1)[0]

    @property
    def short_name(self) -> str:
        return self.full_name.split("/", 1)[1]


@dataclass(frozen=True, slots=True)
class ActionSpec:
    """An action (.action: goal --- result --- feedback) and the 7 messages actionlib generates from it."""

    full_name: str
    goal: MsgSpec
    result: MsgSpec
    feedback: MsgSpec
    #: FooAction, FooActionGoal, FooActionResult, FooActionFeedback, FooGoal, FooResult, FooFeedback
    generated: tuple[MsgSpec, ...] = field(default=())
    text: str = ""
    path: str | None = None

    @property
    def package(self) -> str:
        return self.full_name.split("/", 1)[0]

    @property
    def short_name(self) -> str:
        return self.full_name.split("/", 1)[1]

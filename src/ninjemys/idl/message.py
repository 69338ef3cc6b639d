"""Runtime base class of generated message classes, and the helpers their generated code calls.

Generated classes (see :mod:`ninjemys.idl.codegen`) define the per-type hot paths (``__init__``,
``_ser``, ``deserialize_from``); this module holds what is the same for every type: the genpy-compatible
surface (``serialize``/``deserialize``, ``__eq__``, the YAML ``__str__`` that ``rostopic echo``
prints, pickling and copying), the slow-path error diagnosis that names the offending field, and the
conversions of array values to wire bytes.
"""

from __future__ import annotations

import struct
from collections.abc import Callable, Iterable

from ninjemys.errors import DeserializationError, SerializationError
from ninjemys.idl.arrays import NUMPY_DTYPES, NumericArray
from ninjemys.idl.spec import PRIMITIVE_FORMATS
from ninjemys.rostime import Duration, Time, TVal

TYPE_CHECKING = False  # importing typing costs ~7 ms of every node's start-up; checkers set it
if TYPE_CHECKING:
    from typing import Any

_SER_ERRORS = (struct.error, TypeError, AttributeError, ValueError, OverflowError, UnicodeError, IndexError)
_pack_len = struct.Struct("<I").pack
_pack_tagged = struct.Struct("<IB").pack
_DESER_ERRORS = (struct.error, ValueError, IndexError, TypeError, UnicodeError, MemoryError, OverflowError)


class ServiceClass:
    """Base of every generated service class: its type, checksum and the request and response classes
    (genpy's service classes carry the same four attributes)."""

    __slots__ = ()
    _type = ""
    _md5sum = ""
    _request_class: type[Message]
    _response_class: type[Message]


class Message:
    """Base of every generated message class (genpy.Message's surface)."""

    #: like genpy: subscribers may attach the publisher's connection header to a received message
    __slots__ = ("_connection_header",)
    _type = ""
    _md5sum = ""
    _full_text = ""
    _has_header = False
    _slot_types: tuple[str, ...] = ()
    #: the spec's fields as (name, FieldType), for diagnosis and generic walkers
    _fields: tuple[Any, ...] = ()

    if TYPE_CHECKING:
        # generated classes add their fields (and services their _request_class, ...) at run time, so
        # to a type checker every field of a message is Any: code reads and writes them freely
        def __init__(self, *args: Any, **kwds: Any) -> None: ...

        def __getattr__(self, name: str) -> Any: ...

        def __setattr__(self, name: str, value: Any) -> None: ...

    # --- serialization -------------------------------------------------------------------------
    def _ser(self, w: Any) -> None:  # generated per class
        raise TypeError(f"{type(self).__name__} is not a generated message class (use idl.loader)")

    def serialize_to_bytes(self) -> bytes:
        """The message in ROS 1 wire format (the fast path the runtime uses)."""
        parts: list[Any] = []
        try:
            self._ser(parts.append)
        except _SER_ERRORS as exc:
            raise diagnose(self, exc) from None
        return b"".join(parts)

    def serialize_framed(self) -> bytes:
        """``uint32 len`` + the wire bytes, joined in one copy: a TCPROS frame, ready to send."""
        return b"".join(self.frame_parts()[1])

    def frame_parts(self) -> tuple[int, list[Any]]:
        """A TCPROS frame unjoined: (total length, [``uint32 len``, wire pieces...]). The pieces are
        bytes-like with one byte per item; a big array is the caller's own buffer, not a copy, so
        a 6 MB image can go to the socket with ``sendmsg`` and no copy in Python."""
        parts: list[Any] = [b""]
        try:
            self._ser(parts.append)
        except _SER_ERRORS as exc:
            raise diagnose(self, exc) from None
        size = sum(map(len, parts))
        parts[0] = _pack_len(size)
        return size + 4, parts

    #: generated classes set it when their ``_wire_frame`` is the fused one (no array of any length)
    _wire_small = False

    def _wire_frame(self, _tag: int = 0) -> bytes:
        """The whole TCPROS frame in one bytes object; with ``_tag``, as an SHMROS inline frame (the
        length counts the tag byte 0 that follows it). Small types generate a fused version
        (:func:`ninjemys.idl.codegen._wire_frame`); this one is their fallback, and names the bad field."""
        total, parts = self.frame_parts()
        if _tag:
            parts[0] = _pack_tagged(total - 3, 0)
        return b"".join(parts)

    def serialize(self, buff: Any) -> None:
        """genpy API: write the wire bytes into a file-like ``buff`` (e.g. ``io.BytesIO``)."""
        buff.write(self.serialize_to_bytes())

    def serialize_numpy(self, buff: Any, numpy: Any = None) -> None:
        """genpy API; numpy arrays are accepted by :meth:`serialize` as well."""
        self.serialize(buff)

    @classmethod
    def deserialize_from(cls, buf: bytes | bytearray | memoryview) -> Message:  # generated per class
        """Decode wire bytes into a new instance. Large arrays stay views into ``buf`` (do not mutate it).

        Raises DeserializationError for truncated input or length prefixes beyond the buffer.
        """
        raise TypeError(f"{cls.__name__} is not a generated message class (use idl.loader)")

    def deserialize(self, data: bytes | bytearray | memoryview) -> Message:
        """genpy API: fill this instance from wire bytes and return it."""
        other = self.deserialize_from(data)
        for name in self.__slots__:
            setattr(self, name, getattr(other, name))
        return self

    def deserialize_numpy(self, data: bytes | bytearray | memoryview, numpy: Any = None) -> Message:
        """genpy API: like :meth:`deserialize`, with numeric arrays as numpy arrays (zero-copy)."""
        self.deserialize(data)
        _numpyfy(self)
        return self

    # --- genpy's generic surface ---------------------------------------------------------------
    def _get_types(self) -> tuple[str, ...]:
        return self._slot_types

    def _check_types(self, exc: Exception | None = None) -> None:
        problem = find_type_problem(self)
        if problem is not None:
            raise SerializationError(problem)
        if exc is not None:
            raise SerializationError(str(exc))

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, self.__class__):
            return False
        for name in self.__slots__:
            mine, theirs = getattr(self, name), getattr(other, name)
            if mine != theirs:
                # a fixed array is a list when built and a tuple when received (as in genpy);
                # unlike genpy, equal values compare equal whichever sequence type holds them
                if isinstance(mine, list | tuple) and isinstance(theirs, list | tuple):
                    if list(mine) == list(theirs):
                        continue
                return False
        return True

    def __ne__(self, other: object) -> bool:
        return not self.__eq__(other)

    __hash__ = None  # type: ignore[assignment]

    def __str__(self) -> str:
        return strify_message(self)

    __repr__ = __str__

    def __getstate__(self) -> list[Any]:
        return [_plain(getattr(self, name)) for name in self.__slots__]

    def __setstate__(self, state: list[Any]) -> None:
        for name, value in zip(self.__slots__, state, strict=True):
            setattr(self, name, value)

    def __copy__(self) -> Message:
        new = self.__class__.__new__(self.__class__)
        for name in self.__slots__:
            setattr(new, name, getattr(self, name))
        return new

    def __deepcopy__(self, memo: dict) -> Message:
        import copy

        new = self.__class__.__new__(self.__class__)
        for name in self.__slots__:
            setattr(new, name, copy.deepcopy(_plain(getattr(self, name)), memo))
        return new


def _plain(value: Any) -> Any:
    """Views become owned values (for pickling/deep copies): memoryview -> bytes, NumericArray -> list."""
    if isinstance(value, memoryview):
        return value.tobytes()
    if isinstance(value, NumericArray):
        return value.tolist()
    return value


def _numpyfy(msg: Message) -> None:
    import numpy

    for name, ftype in msg._fields:
        value = getattr(msg, name)
        if ftype.is_message:
            for sub in value if ftype.is_array else (value,):
                _numpyfy(sub)
        elif ftype.is_array and ftype.base in PRIMITIVE_FORMATS and ftype.base not in ("uint8", "char"):
            fmt = PRIMITIVE_FORMATS[ftype.base][0]
            if isinstance(value, NumericArray):
                setattr(msg, name, numpy.asarray(value))
            else:
                setattr(msg, name, numpy.array(value, dtype=NUMPY_DTYPES[fmt]))


# --- helpers called by generated code -----------------------------------------------------------
DESER_ERRORS = _DESER_ERRORS
SER_ERRORS = _SER_ERRORS
pack_len = _pack_len


def as_view(buf: Any) -> memoryview:
    """A flat unsigned-byte memoryview over any buffer (bytes, bytearray, memoryview, numpy ...)."""
    try:
        mv = buf if isinstance(buf, memoryview) else memoryview(buf)
        if mv.format != "B" or mv.ndim != 1:
            mv = mv.cast("B")
    except (TypeError, ValueError) as exc:
        raise DeserializationError(f"cannot decode a {type(buf).__name__}: {exc}") from None
    return mv


def deser_failed(cls: type[Message], mv: Any, exc: BaseException) -> DeserializationError:
    return DeserializationError(f"{cls._type}: cannot decode {len(mv)} bytes: {type(exc).__name__}: {exc}")


def short_buffer(type_name: str, what: str, need: int, have: int) -> DeserializationError:
    return DeserializationError(
        f"{type_name}.{what}: buffer too short (length prefix says {need} bytes/items, {have} bytes left)"
    )


def u8_buffer(value: Any) -> Any:
    """A ``uint8[]``/``char[]`` value as a bytes-like object for the wire (no copy for buffers)."""
    if isinstance(value, bytes | bytearray):
        return value
    if isinstance(value, memoryview):
        return value if value.format == "B" and value.ndim == 1 else value.cast("B")
    if isinstance(value, str):
        return value.encode("latin-1")
    if type(value).__module__ == "numpy":
        array = value.astype("u1", copy=False)
        if array.ndim and array.flags.c_contiguous:
            # the array's own memory: a camera frame is copied once, into the socket or the
            # shared-memory ring, not first into a bytes object (publishers that keep a frame past
            # publish, for a lagging subscriber or a latch, join it into bytes of their own)
            view = memoryview(array)
            return view if array.ndim == 1 else view.cast("B")
        return array.tobytes()
    return bytes(value)  # list/tuple of ints: ValueError/TypeError on bad items -> diagnosis


_ARRAY_TYPECODES = {
    "b": "b",
    "B": "B",
    "h": "h",
    "H": "H",
    "i": "i",
    "I": "I",
    "q": "q",
    "Q": "Q",
    "f": "f",
    "d": "d",
}


_ARRAY_STRUCTS: dict[tuple[str, int], struct.Struct] = {}


def _array_struct(fmt: str, count: int) -> struct.Struct:
    if len(_ARRAY_STRUCTS) > 512:  # bounded: array lengths vary in some streams
        _ARRAY_STRUCTS.clear()
    packer = _ARRAY_STRUCTS[(fmt, count)] = struct.Struct(f"<{count}{fmt}")
    return packer


def pack_numeric(value: Any, fmt: str) -> Any:
    """A numeric array value as little-endian wire bytes (views are written back without conversion)."""
    cls = value.__class__
    if cls is list or cls is tuple:
        packer = _ARRAY_STRUCTS.get((fmt, len(value))) or _array_struct(fmt, len(value))
        return packer.pack(*value)
    if cls is NumericArray and value.format == fmt:
        return value.raw_bytes()
    if type(value).__module__ == "numpy":
        return value.astype(NUMPY_DTYPES[fmt], copy=False).tobytes()
    if fmt == "?":
        return struct.pack(f"<{len(value)}B", *value)
    return struct.pack(f"<{len(value)}{fmt}", *list(value))


def fixed_u8(value: Any, size: int) -> bytes:
    """A fixed ``uint8[N]``/``char[N]`` value as exactly N bytes."""
    data = bytes(u8_buffer(value))
    if len(data) != size:
        raise ValueError(f"expected {size} bytes, got {len(data)}")
    return data


def encode_string(value: Any) -> bytes:
    if isinstance(value, str):
        return value.encode("utf-8")
    if isinstance(value, bytes):
        return value
    raise TypeError(f"expected str, got {type(value).__name__}")


# --- diagnosis of serialization errors (slow path only) -----------------------------------------
_INT_RANGES = {
    "int8": (-(1 << 7), (1 << 7) - 1),
    "byte": (-(1 << 7), (1 << 7) - 1),
    "uint8": (0, (1 << 8) - 1),
    "char": (0, (1 << 8) - 1),
    "int16": (-(1 << 15), (1 << 15) - 1),
    "uint16": (0, (1 << 16) - 1),
    "int32": (-(1 << 31), (1 << 31) - 1),
    "uint32": (0, (1 << 32) - 1),
    "int64": (-(1 << 63), (1 << 63) - 1),
    "uint64": (0, (1 << 64) - 1),
}


def _type_label(value: Any) -> str:
    return type(value).__name__


def _check_scalar(base: str, value: Any) -> str | None:
    """None when ``value`` can be written as ``base``, else 'expected X, got Y'."""
    if base in _INT_RANGES:
        if isinstance(value, bool) or not hasattr(value, "__index__") or isinstance(value, float):
            if not isinstance(value, bool):
                return f"expected {base} (int), got {_type_label(value)}"
        lo, hi = _INT_RANGES[base]
        if not lo <= int(value) <= hi:
            return f"value {int(value)} out of range for {base} [{lo}, {hi}]"
        return None
    if base in ("float32", "float64"):
        if (
            isinstance(value, str | bytes)
            or not isinstance(value, int | float)
            and not hasattr(value, "__float__")
        ):
            return f"expected {base} (float), got {_type_label(value)}"
        if base == "float32":
            try:
                struct.pack("<f", value)
            except OverflowError:
                return f"value {value!r} out of range for float32"
        return None
    if base == "bool":
        if value not in (True, False, 0, 1):
            return f"expected bool, got {_type_label(value)} {value!r}"
        return None
    if base == "string":
        if not isinstance(value, str | bytes):
            return f"expected string (str or bytes), got {_type_label(value)}"
        return None
    if base == "time":
        if not isinstance(value, Time) and not (isinstance(value, TVal) and not isinstance(value, Duration)):
            return f"expected Time, got {_type_label(value)}"
        return _check_tval(value, "uint32")
    if base == "duration":
        if not isinstance(value, Duration):
            return f"expected Duration, got {_type_label(value)}"
        return _check_tval(value, "int32")
    return None


def _check_tval(value: TVal, kind: str) -> str | None:
    lo, hi = _INT_RANGES[kind]
    for part in ("secs", "nsecs"):
        number = getattr(value, part)
        if not isinstance(number, int) or not lo <= number <= hi:
            return f"{part}={number!r} does not fit the wire's {kind}"
    return None


def find_type_problem(msg: Any, prefix: str | None = None) -> str | None:
    """Walk a message and describe the first field whose value cannot be serialized, or None."""
    type_name = getattr(msg, "_type", type(msg).__name__)
    label = prefix or type_name
    for name, ftype in getattr(type(msg), "_fields", ()):
        where = f"{label}.{name}"
        try:
            value = getattr(msg, name)
        except AttributeError:
            return f"{where}: field is not set"
        problem = _check_value(ftype, value, where)
        if problem is not None:
            return problem
    return None


def _check_value(ftype: Any, value: Any, where: str) -> str | None:
    if ftype.is_array:
        if ftype.base in ("uint8", "char") and isinstance(value, bytes | bytearray | memoryview):
            if ftype.array_len is not None and len(value) != ftype.array_len:
                return f"{where}: expected {ftype} ({ftype.array_len} bytes), got {len(value)} bytes"
            return None
        is_numpy = type(value).__module__ == "numpy"
        if not isinstance(value, list | tuple | NumericArray) and not is_numpy:
            expected = "bytes or list of int" if ftype.base in ("uint8", "char") else "list or tuple"
            return f"{where}: expected {ftype} ({expected}), got {_type_label(value)}"
        if ftype.array_len is not None and len(value) != ftype.array_len:
            return f"{where}: expected {ftype} with {ftype.array_len} elements, got {len(value)}"
        if is_numpy:
            return None
        for i, item in enumerate(value):
            problem = _check_item(ftype.base, item, f"{where}[{i}]", ftype)
            if problem is not None:
                return problem
        return None
    return _check_item(ftype.base, value, where, ftype)


def _check_item(base: str, value: Any, where: str, ftype: Any) -> str | None:
    if ftype.is_message:
        if not isinstance(value, Message):
            return f"{where}: expected {base}, got {_type_label(value)}"
        if value._type != base:
            return f"{where}: expected {base}, got {value._type}"
        return find_type_problem(value, where)
    problem = _check_scalar(base, value)
    if problem is not None:
        return f"{where}: {problem}"
    if base == "string" and isinstance(value, str):
        try:
            value.encode("utf-8")
        except UnicodeEncodeError as exc:
            return f"{where}: string is not encodable as UTF-8 ({exc.reason})"
    return None


def diagnose(msg: Message, exc: BaseException) -> SerializationError:
    """Turn a low-level failure of the fast path into an error naming the field and the types."""
    problem = find_type_problem(msg)
    if problem is None:
        problem = f"{msg._type}: cannot serialize: {type(exc).__name__}: {exc}"
    return SerializationError(problem)


# --- the YAML form printed by rostopic echo (genpy strify_message) ------------------------------
def _yaml_string(value: str) -> str:
    """PyYAML's double-quoted form, as genpy prints strings.

    Printable ASCII without quotes or backslashes comes out verbatim between quotes unless PyYAML
    would fold it (only at spaces, past column ~80): that common case skips importing PyYAML, which
    costs a ``rostopic echo`` process 25-60 ms.
    """
    if (
        value.isascii()
        and value.isprintable()
        and '"' not in value
        and "\\" not in value
        and (len(value) <= 78 or " " not in value)
    ):
        return f'"{value}"'
    import yaml

    return yaml.dump(value, default_style='"').rstrip("\n")


def strify_message(
    val: Any,
    indent: str = "",
    time_offset: Time | None = None,
    current_time: Time | None = None,
    field_filter: Callable[[Any], Iterable[str]] | None = None,
    fixed_numeric_width: int | None = None,
) -> str:
    """Render a value the way genpy/rostopic echo do (YAML-ish, nested indentation by two spaces).

    The parameters are genpy's: ``time_offset`` prints times relative to it, ``field_filter(msg)``
    selects the fields shown, ``fixed_numeric_width`` pads numbers (``current_time`` is unused, as in
    genpy).
    """
    t = type(val)
    if fixed_numeric_width is not None and t in (int, float):
        if t is float:
            text = f"%.{fixed_numeric_width}f" % val
            return text[: max(text.find("."), fixed_numeric_width)]
        return f"%{fixed_numeric_width}d" % val
    if t in (int, float, bool):
        return str(val)
    if t is str:
        return _yaml_string(val) if val else "''"
    if isinstance(val, TVal):
        if time_offset is not None and isinstance(val, Time):
            val = val - time_offset
        if fixed_numeric_width is not None:
            width = f"%{fixed_numeric_width}d"
            return f"\n{indent}secs: {width % val.secs}\n{indent}nsecs: {width % val.nsecs}"
        return f"\n{indent}secs: {val.secs}\n{indent}nsecs: {val.nsecs:9d}"
    if isinstance(val, NumericArray):
        val = val.tolist()
        t = list
    if t in (list, tuple):
        if not val:
            return "[]"
        first = val[0]
        if type(first) in (int, float) and fixed_numeric_width is not None:
            parts = "".join(
                strify_message(v, indent, time_offset, current_time, field_filter, fixed_numeric_width) + ", "
                for v in val
            )
            return "[" + parts.rstrip(", ") + "]"
        if isinstance(first, str):
            import yaml

            text = yaml.dump(list(val)).rstrip("\n")
            if text[0] == "[":
                return text
            return "\n" + "\n".join(indent + line for line in text.splitlines())
        if type(first) in (int, float, bool):
            return str(list(val))
        pref = indent + "- "
        sub = indent + "  "
        return "\n" + "\n".join(
            pref + strify_message(v, sub, time_offset, current_time, field_filter, fixed_numeric_width)
            for v in val
        )
    if isinstance(val, Message):
        shown = set(field_filter(val)) if field_filter is not None else None
        sub = "  " + indent
        lines = []
        for name, type_ in zip(val.__slots__, val._slot_types, strict=True):
            if shown is not None and name not in shown:
                continue
            value = getattr(val, name)
            if "uint8[" in type_ and isinstance(value, bytes | bytearray | memoryview):
                value = list(value)
            text = strify_message(value, sub, time_offset, current_time, field_filter, fixed_numeric_width)
            lines.append(f"{indent}{name}: {text}")
        body = "\n".join(lines)
        return "\n" + body if indent else body
    if isinstance(val, memoryview):
        return str(val.tobytes())
    if type(val).__module__ == "numpy" and hasattr(val, "tolist"):
        return strify_message(
            val.tolist(), indent, time_offset, current_time, field_filter, fixed_numeric_width
        )
    return str(val)


def bad_args(msg: Message, args: tuple[Any, ...], kwds: dict[str, Any]) -> None:
    """Raise the error genpy raises for a constructor call that does not fit the fields."""
    if args and kwds:
        raise TypeError(f"{msg._type}: constructor takes positional args OR keywords, not both")
    if args:
        raise TypeError(
            f"{msg._type}: invalid number of arguments, expected {len(msg.__slots__)} "
            f"({', '.join(msg.__slots__)}), got {len(args)}"
        )
    unknown = ", ".join(sorted(kwds))
    raise AttributeError(f"{unknown} is not an attribute of {msg._type}")

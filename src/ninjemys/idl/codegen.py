"""Code generation: a message spec -> Python source of its class (a pure function of its inputs).

The generated ``_ser``/``deserialize_from`` are straight-line code specialised for one type:

* nested messages that are not in arrays are *flattened* into their parent's code, so a run of
  fixed-size fields — also across nesting, e.g. ``Header.seq`` + ``stamp`` + the length of
  ``frame_id``, or a Pose's seven float64 — is read or written by ONE precompiled ``struct.Struct``
  call; the length prefix of a following string or array joins the run too;
* loops over arrays of messages have the element's code inlined (no call per element);
* ``uint8[]``/``char[]`` and other numeric arrays are moved as blocks: views on the way in
  (see :mod:`ninjemys.idl.arrays`), one ``join`` of buffers on the way out;
* every length prefix is checked against the bytes that remain before anything is allocated or
  looped over, so a bogus length raises DeserializationError instead of allocating gigabytes.

The source refers to a few runtime names that the loader puts in the namespace (``_Message``,
``_Time``, ``_Duration``, ``_NumArr``, helpers of :mod:`ninjemys.idl.message`) and to one class per
nested type, named by :func:`class_ref`.
"""

from __future__ import annotations

import keyword
import math
from collections.abc import Callable

from ninjemys.errors import DefinitionError
from ninjemys.idl.arrays import LITTLE_ENDIAN_HOST
from ninjemys.idl.spec import PRIMITIVE_FORMATS, Constant, Field, FieldType, MsgSpec

Lookup = Callable[[str], MsgSpec]

_TIME_FMT = {"time": "II", "duration": "ii"}
_FLOATS = ("float32", "float64")
#: element count allowed for arrays of zero-size elements (e.g. std_msgs/Empty[]): no bytes to check
MAX_EMPTY_ELEMENTS = 1 << 20


def class_ref(type_name: str) -> str:
    """The namespace name under which the generated code expects the class of ``type_name``."""
    return "_C_" + type_name.replace("/", "__")


def min_size(spec: MsgSpec, lookup: Lookup) -> int:
    """The smallest number of wire bytes any instance of ``spec`` takes."""
    return sum(_min_field_size(f.type, lookup) for f in spec.fields)


def _min_field_size(ftype: FieldType, lookup: Lookup) -> int:
    if not ftype.is_array:
        return _min_elem_size(ftype.base, lookup)
    if ftype.array_len is None:
        return 4  # the length prefix of an empty variable-length array
    return ftype.array_len * _min_elem_size(ftype.base, lookup)


def _min_elem_size(base: str, lookup: Lookup) -> int:
    if base in PRIMITIVE_FORMATS:
        return PRIMITIVE_FORMATS[base][1]
    if base in _TIME_FMT:
        return 8
    if base == "string":
        return 4
    return min_size(lookup(base), lookup)


def _default_expr(ftype: FieldType) -> str:
    base = ftype.base
    if ftype.is_array:
        if ftype.array_len is None:
            return "b''" if base in ("uint8", "char") else "[]"
        n = ftype.array_len
        if base in ("uint8", "char"):
            return f"b'\\x00' * {n}"
        if base in _FLOATS:
            return f"[0.0] * {n}"
        if base == "bool":
            return f"[False] * {n}"
        if base in PRIMITIVE_FORMATS:
            return f"[0] * {n}"
        if base == "string":
            return f"[''] * {n}"
        elem = _default_expr(FieldType(base))
        return f"[{elem} for _ in range({n})]"
    if base in _FLOATS:
        return "0.0"
    if base == "bool":
        return "False"
    if base in PRIMITIVE_FORMATS:
        return "0"
    if base == "string":
        return "''"
    if base == "time":
        return "_Time()"
    if base == "duration":
        return "_Duration()"
    return f"{class_ref(base)}()"


def _literal(value: object) -> str:
    if isinstance(value, float) and not math.isfinite(value):
        return f"float({str(value)!r})"
    return repr(value)


class _Emitter:
    """Accumulates lines, the pending fixed-size run and the struct formats it needs.

    A plain class, not a dataclass: ``dataclasses`` costs ~5 ms of every node's start-up (the node
    loads rosgraph_msgs/Log and the logger services' types before it returns).
    """

    def __init__(
        self,
        type_name: str,
        lookup: Lookup,
        structs: dict[str, str],
        depth: int = 2,
        bytes_buffer: bool = False,
    ) -> None:
        self.type_name = type_name
        self.lookup = lookup
        self.structs = structs
        self.lines: list[str] = []
        self.depth = depth
        self.counter = 0
        self.run: list[tuple[str, str]] = []  # (format, target-or-argument)
        self.posts: list[str] = []  # statements to run after the run is unpacked
        self.loops = False  # the code has a loop (arrays of messages/strings): no straight-line form
        self.views = False  # the code slices the buffer into views (needs a memoryview, not bytes)
        self.bytes_buffer = bytes_buffer  # the buffer is bytes (set when the type has no views)

    def tmp(self, prefix: str = "v") -> str:
        self.counter += 1
        return f"_{prefix}{self.counter}"

    def emit(self, line: str) -> None:
        self.lines.append("    " * self.depth + line)

    def struct_name(self, fmt: str) -> str:
        name = self.structs.get(fmt)
        if name is None:
            name = f"_S{len(self.structs)}"
            self.structs[fmt] = name
        return name


class _SerEmitter(_Emitter):
    def flush(self) -> None:
        if not self.run:
            return
        fmt = "<" + "".join(f for f, _ in self.run)
        args = ", ".join(a for _, a in self.run)
        self.emit(f"w({self.struct_name(fmt)}.pack({args}))")
        self.run = []

    def fields(self, spec: MsgSpec, obj: str) -> None:
        for f in spec.fields:
            self.value(f.type, f"{obj}.{f.name}")

    def value(self, ftype: FieldType, expr: str) -> None:
        base = ftype.base
        if not ftype.is_array:
            self.scalar(base, expr)
            return
        v = self.tmp()
        self.emit(f"{v} = {expr}")
        n = ftype.array_len
        if base in ("uint8", "char"):
            if n is None:
                self.emit(f"if {v}.__class__ is not bytes: {v} = _u8({v})")
                self.run.append(("I", f"len({v})"))
                self.flush()
                self.emit(f"w({v})")
            else:
                self.emit(f"if {v}.__class__ is not bytes or len({v}) != {n}: {v} = _fixed_u8({v}, {n})")
                self.run.append((f"{n}s", v))
            return
        if base in PRIMITIVE_FORMATS:
            fmt = PRIMITIVE_FORMATS[base][0]
            if n is None:
                self.run.append(("I", f"len({v})"))
                self.flush()
                self.emit(f"w(_pack_num({v}, {fmt!r}))")
            else:
                self.run.append((f"{n}{fmt}", f"*{v}"))
            return
        if n is None:
            self.run.append(("I", f"len({v})"))
        else:
            self.emit(f"if len({v}) != {n}: raise ValueError('expected {n} elements')")
        self.flush()
        e = self.tmp("e")
        self.loops = True
        self.emit(f"for {e} in {v}:")
        self.depth += 1
        self.scalar(base, e)
        self.flush()
        self.depth -= 1

    def scalar(self, base: str, expr: str) -> None:
        if base in PRIMITIVE_FORMATS:
            self.run.append((PRIMITIVE_FORMATS[base][0], expr))
        elif base in _TIME_FMT:
            v = self.tmp()
            self.emit(f"{v} = {expr}")
            self.run.append((_TIME_FMT[base], f"{v}.secs, {v}.nsecs"))
        elif base == "string":
            v = self.tmp()
            self.emit(f"{v} = {expr}")
            self.emit(f"{v} = {v}.encode() if {v}.__class__ is str else _enc({v})")
            self.run.append(("I", f"len({v})"))
            self.flush()
            self.emit(f"w({v})")
        else:
            v = self.tmp()
            self.emit(f"{v} = {expr}")
            self.fields(self.lookup(base), v)


class _DeserEmitter(_Emitter):
    def flush(self) -> None:
        if not self.run:
            return
        fmt = "<" + "".join(f for f, _ in self.run)
        size = _struct_size(fmt)
        targets = [t for _, t in self.run]
        self.emit(f"({', '.join(targets)},) = {self.struct_name(fmt)}.unpack_from(mv, pos)")
        self.emit(f"pos += {size}")
        for line in self.posts:
            self.emit(line)
        self.run = []
        self.posts = []

    def fields(self, spec: MsgSpec, obj: str) -> None:
        for f in spec.fields:
            self.value(f.type, f"{obj}.{f.name}", f.name)

    def check(self, need: str, what: str, shown: str) -> None:
        self.emit(f"if {need} > end - pos: raise _short({self.type_name!r}, {what!r}, {shown}, end - pos)")

    def value(self, ftype: FieldType, target: str, what: str) -> None:
        base = ftype.base
        if not ftype.is_array:
            self.scalar(base, target, what)
            return
        n = ftype.array_len
        if base in PRIMITIVE_FORMATS and n is not None:
            fmt = PRIMITIVE_FORMATS[base][0]
            if base in ("uint8", "char"):
                self.run.append((f"{n}s", target))
                return
            if n > 32:  # a long fixed array: its own unpack into a tuple instead of N temporaries
                self.flush()
                size = n * PRIMITIVE_FORMATS[base][1]
                self.emit(f"{target} = {self.struct_name(f'<{n}{fmt}')}.unpack_from(mv, pos)")
                if base == "bool":
                    self.emit(f"{target} = [x != 0 for x in {target}]")
                self.emit(f"pos += {size}")
                return
            temps = [self.tmp("t") for _ in range(n)]
            if n == 0:
                self.emit(f"{target} = {'[]' if base == 'bool' else '()'}")
                return
            self.run.extend((fmt, t) for t in temps)
            joined = ", ".join(temps)
            if base == "bool":
                self.posts.append(f"{target} = [bool(x) for x in ({joined},)]")
            else:
                self.posts.append(f"{target} = ({joined},)")
            return
        if n is None:
            count = self.tmp("n")
            self.run.append(("I", count))
            self.flush()
        else:
            self.flush()
            count = str(n)
        if base in PRIMITIVE_FORMATS:  # variable-length numeric block
            fmt, size = PRIMITIVE_FORMATS[base]
            nbytes = count
            if size > 1:
                nbytes = self.tmp("b")
                self.emit(f"{nbytes} = {count} * {size}")
            self.check(nbytes, what, count)
            self.views = self.views or base != "bool"
            if base in ("uint8", "char"):
                self.emit(f"{target} = mv[pos:pos + {count}]")
            elif base == "bool":
                self.emit(f"{target} = [x != 0 for x in mv[pos:pos + {count}]]")
            else:
                if LITTLE_ENDIAN_HOST:  # a typed view straight over the wire bytes
                    arr = self.tmp("a")
                    self.emit(f"{arr} = _new(_NumArr)")
                    self.emit(f"{arr}._raw = mv[pos:pos + {nbytes}]")
                    self.emit(f"{arr}._fmt = {fmt!r}")
                    self.emit(f"{target} = {arr}")
                else:
                    self.emit(f"{target} = _struct.unpack_from('<%d{fmt}' % {count}, mv, pos)")
            self.emit(f"pos += {nbytes}")
            return
        elem_size = _min_elem_size(base, self.lookup)
        if elem_size:
            self.check(f"{count} * {elem_size}", what, count)
        else:
            self.emit(
                f"if {count} > {MAX_EMPTY_ELEMENTS}: raise _short({self.type_name!r}, {what!r}, {count}, end - pos)"
            )
        lst = self.tmp("l")
        self.emit(f"{lst} = []")
        self.emit(f"for _ in range({count}):")
        self.depth += 1
        elem = self.tmp("x")
        self.scalar(base, elem, what)
        self.flush()
        self.emit(f"{lst}.append({elem})")
        self.depth -= 1
        self.emit(f"{target} = {lst}")

    def scalar(self, base: str, target: str, what: str) -> None:
        if base in PRIMITIVE_FORMATS:
            if base == "bool":
                t = self.tmp("t")
                self.run.append(("B", t))
                self.posts.append(f"{target} = {t} != 0")
            else:
                self.run.append((PRIMITIVE_FORMATS[base][0], target))
        elif base in _TIME_FMT:
            v = self.tmp("o")
            self.emit(f"{v} = _new({'_Time' if base == 'time' else '_Duration'})")
            self.emit(f"{target} = {v}")
            self.run.append((_TIME_FMT[base], f"{v}.secs, {v}.nsecs"))
            if base == "time":
                self.posts.append(f"if {v}.nsecs >= 1000000000: {v}.canon()")
            else:
                self.posts.append(f"if not 0 <= {v}.nsecs < 1000000000: {v}.canon()")
        elif base == "string":
            n = self.tmp("n")
            self.run.append(("I", n))
            self.flush()
            self.check(n, what, n)
            if self.bytes_buffer:  # without views the buffer is bytes: slice and decode directly
                self.emit(f"{target} = mv[pos:pos + {n}].decode('utf-8', 'replace')")
            else:  # sb: the bytes object when given one (cheaper slices), else the memoryview
                self.emit(f"{target} = str(sb[pos:pos + {n}], 'utf-8', 'replace')")
            self.emit(f"pos += {n}")
        else:
            v = self.tmp("o")
            self.emit(f"{v} = _new({class_ref(base)})")
            self.emit(f"{target} = {v}")
            self.fields(self.lookup(base), v)


def _struct_size(fmt: str) -> int:
    import struct

    return struct.calcsize(fmt)


def _reserved(name: str) -> bool:
    return keyword.iskeyword(name) or name == "self"


def python_safe(spec: MsgSpec) -> MsgSpec:
    """genpy's rule for names Python cannot take: a field or constant named like a keyword (or
    ``self``) is ``name_`` on the class (``string in`` of a .srv is ``req.in_``, as in ROS 1). The
    wire format, the definition text and the md5sum keep the name as written."""
    if not any(_reserved(f.name) for f in spec.fields) and not any(_reserved(c.name) for c in spec.constants):
        return spec
    fields = tuple(Field(f.name + "_", f.type, f.raw_type) if _reserved(f.name) else f for f in spec.fields)
    constants = tuple(
        Constant(c.type, c.name + "_", c.value, c.value_text) if _reserved(c.name) else c
        for c in spec.constants
    )
    return MsgSpec(spec.full_name, fields, constants, spec.text, spec.path)


def _safe_lookup(lookup: Lookup) -> Lookup:
    return lambda name: python_safe(lookup(name))


def _check_names(spec: MsgSpec) -> None:
    for f in spec.fields:
        if f.name.startswith("_"):
            raise DefinitionError(
                f"{spec.full_name}: field name {f.name!r} cannot be used in Python", spec.path
            )


def _straight_serializers(ser_lines: list[str]) -> list[str]:
    """``frame_parts`` and ``serialize_to_bytes`` for a type whose ``_ser`` is straight-line code:
    each ``w(x)`` becomes a local, so there is no list, no bound ``append`` and no length sum to
    pay per message (2-4x cheaper than the generic versions; every publish and service call pays
    it). On any error they fall back to the generic versions, which say which field was wrong."""
    stmts: list[str] = []
    parts: list[str] = []
    for line in ser_lines:
        stmt = line.strip()
        if stmt.startswith("w(") and stmt.endswith(")"):
            name = f"_p{len(parts)}"
            parts.append(name)
            stmt = f"{name} = {stmt[2:-1]}"
        stmts.append(stmt)
    body = [f"            {stmt}" for stmt in stmts] or ["            pass"]
    size = " + ".join(f"len({p})" for p in parts) or "0"
    joined = parts[0] if len(parts) == 1 else f'b"".join(({", ".join(parts)},))' if parts else 'b""'
    return [
        "",
        "    def frame_parts(self):",
        "        try:",
        *body,
        "        except _SER_ERRORS:",
        "            return _Message.frame_parts(self)",
        f"        _n = {size}",
        f"        return _n + 4, [_pack_len(_n), {', '.join(parts)}]"
        if parts
        else "        return 4, [_pack_len(0)]",
        "",
        "    def serialize_to_bytes(self):",
        "        try:",
        *body,
        "        except _SER_ERRORS:",
        "            return _Message.serialize_to_bytes(self)",
        f"        return {joined}",
    ]


def generate_class_source(spec: MsgSpec, lookup: Lookup, md5sum: str, full_text: str) -> str:
    """Python source defining the class for ``spec`` (named by its short name) and its structs."""
    spec = python_safe(spec)
    _check_names(spec)
    lookup = _safe_lookup(lookup)  # nested types get Python-safe names too
    cls = spec.short_name
    names = [f.name for f in spec.fields]
    structs: dict[str, str] = {}
    body: list[str] = [
        f"class {cls}(_Message):",
        f"    __slots__ = {tuple(names)!r}",
        f"    _type = {spec.full_name!r}",
        f"    _md5sum = {md5sum!r}",
        f"    _full_text = {full_text!r}",
        f"    _has_header = {spec.has_header!r}",
        f"    _slot_types = {tuple(str(f.type) for f in spec.fields)!r}",
    ]
    for c in spec.constants:
        body.append(f"    {c.name} = {_literal(c.value)}")

    # __init__: positional (all fields) or keywords (any subset); None means "the default"
    body.append("")
    body.append("    def __init__(self, *args, **kwds):")
    if names:
        params = [f"_a{i}" for i in range(len(names))]
        body.append("        if args:")
        body.append(f"            if kwds or len(args) != {len(names)}: _bad_args(self, args, kwds)")
        body.append(f"            ({', '.join(params)},) = args")
        body.append("        else:")
        for p, n in zip(params, names, strict=True):
            body.append(f"            {p} = kwds.pop({n!r}, None)")
        body.append("            if kwds: _bad_args(self, args, kwds)")
        for p, f in zip(params, spec.fields, strict=True):
            body.append(f"        self.{f.name} = {_default_expr(f.type)} if {p} is None else {p}")
    else:
        body.append("        if args or kwds: _bad_args(self, args, kwds)")

    ser = _SerEmitter(spec.full_name, lookup, structs)
    ser.fields(spec, "self")
    ser.flush()
    _ser_structs = dict(structs)
    body.append("")
    body.append("    def _ser(self, w):")
    body.extend(ser.lines or ["        pass"])
    if not ser.loops:
        body.extend(_straight_serializers(ser.lines))

    de = _DeserEmitter(spec.full_name, lookup, structs, depth=3)
    de.fields(spec, "o")
    de.flush()
    if not de.views:  # regenerate for a bytes buffer: strings decode straight from bytes slices
        structs.clear()
        structs.update(_ser_structs)
        de = _DeserEmitter(spec.full_name, lookup, structs, depth=3, bytes_buffer=True)
        de.fields(spec, "o")
        de.flush()
    body.append("")
    body.append("    @classmethod")
    body.append("    def deserialize_from(cls, buf):")
    if de.views:
        body.append("        mv = memoryview(buf) if buf.__class__ is bytes else _view(buf)")
        body.append("        sb = buf if buf.__class__ is bytes else mv")
    else:  # strings and numbers only: a bytes copy of other buffers, sliced directly
        body.append("        mv = buf if buf.__class__ is bytes else _view(buf).tobytes()")
    body.append("        end = len(mv)")
    body.append("        pos = 0")
    body.append("        try:")
    body.append("            o = _new(cls)")
    body.extend(de.lines)
    body.append("        except _DESER_ERRORS as exc:")
    body.append("            raise _deser_failed(cls, mv, exc) from None")
    body.append("        return o")

    head = [f"{name} = _struct.Struct({fmt!r})" for fmt, name in structs.items()]
    return "\n".join(head + [""] + body) + "\n"

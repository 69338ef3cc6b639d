"""C++ message and service headers from parsed specs, in the layout roscpp's templates expect.

roscpp does not read ``.msg`` files: a C++ node includes ``<pkg/Type.h>``, whose class template
``pkg::Type_<ContainerAllocator>`` carries the fields, and whose specialisations of roscpp's traits
tell it the md5sum, type name and full definition (``ros::message_traits::MD5Sum`` / ``DataType`` /
``Definition``, ``IsFixedSize``, ``HasHeader``), how to write and read it
(``ros::serialization::Serializer``, field by field, in order) and how to print it
(``ros::message_operations::Printer``, used by ``operator<<``). A service header adds the
``pkg::Srv`` struct (``Request``/``Response``) and ``ros::service_traits``. ROS 1's gencpp writes
these from its templates; this module writes them from ninjemys' own specs (:mod:`ninjemys.idl`), so
message packages that only ninjemys ships (control_msgs, gazebo_msgs, ...) can be used from C++.

Pure functions of their inputs: no file is read or written here (:mod:`ninjemys.packages.cpp_msgs`
decides what to write where). The md5sum and the full text are passed in, computed by the same code
that Python nodes use, so a C++ node and a Python node always agree on the wire.
"""

from __future__ import annotations

from collections.abc import Callable

from ninjemys.idl.spec import FieldType, MsgSpec, SrvSpec

Lookup = Callable[[str], MsgSpec]

#: how roscpp spells each builtin type (bool is a byte on the wire and in the struct)
_STRING = (
    "std::basic_string<char, std::char_traits<char>, "
    "typename std::allocator_traits<ContainerAllocator>::template rebind_alloc<char>>"
)
CPP_BUILTINS: dict[str, str] = {
    "bool": "uint8_t",
    "byte": "int8_t",
    "char": "uint8_t",
    "int8": "int8_t",
    "uint8": "uint8_t",
    "int16": "int16_t",
    "uint16": "uint16_t",
    "int32": "int32_t",
    "uint32": "uint32_t",
    "int64": "int64_t",
    "uint64": "uint64_t",
    "float32": "float",
    "float64": "double",
    "string": _STRING,
    "time": "ros::Time",
    "duration": "ros::Duration",
}
_SIGNED = ("byte", "int8", "int16", "int32", "int64", "char")
_UNSIGNED = ("uint8", "uint16", "uint32", "uint64")
#: builtins that are plain values in C++ (everything else takes the allocator in its constructor)
_NO_ALLOCATOR = (*_SIGNED, *_UNSIGNED, "float32", "float64", "bool", "time", "duration")


def cpp_element_type(base: str) -> str:
    """The C++ type of one element: ``double``, `` ::geometry_msgs::Point_<ContainerAllocator> ``."""
    builtin = CPP_BUILTINS.get(base)
    if builtin is not None:
        return builtin
    package, name = base.split("/", 1)
    return f" ::{package}::{name}_<ContainerAllocator> "


def cpp_field_type(ftype: FieldType) -> str:
    """The C++ type of a field: the element type, in a std::vector or a boost::array for arrays."""
    element = cpp_element_type(ftype.base)
    if not ftype.is_array:
        return element
    if ftype.array_len is None:
        return (
            f"std::vector<{element}, typename std::allocator_traits<ContainerAllocator>"
            f"::template rebind_alloc<{element}>>"
        )
    return f"boost::array<{element}, {ftype.array_len}> "


def _default(base: str) -> str:
    """The initializer of a scalar of this type ('' for strings, times and messages)."""
    if base in _SIGNED or base in _UNSIGNED:
        return "0"
    if base in ("float32", "float64"):
        return "0.0"
    if base == "bool":
        return "false"
    return ""


def escape(text: str) -> str:
    """A string's content as a C string literal body (backslashes and quotes escaped)."""
    return text.replace("\\", "\\\\").replace('"', '\\"')


def definition_literal(full_text: str) -> str:
    """The full definition as adjacent C string literals, one per line (each ends in ``\\n``):
    compilers limit the length of one literal, not of a concatenation."""
    lines = full_text.splitlines() or [""]
    return "".join(f'"{escape(line)}\\n"\n' for line in lines)


def is_fixed_size(spec: MsgSpec, lookup: Lookup) -> bool:
    """True when every instance has the same wire size: no strings, no variable-length arrays, in
    the message or in any message it contains (roscpp then sizes buffers without looking)."""
    for f in spec.fields:
        if f.type.is_array and f.type.array_len is None:
            return False
        if f.type.base == "string":
            return False
    return all(is_fixed_size(lookup(dep), lookup) for dep in spec.dependencies)


def _guard(package: str, name: str) -> str:
    return f"{package.upper()}_MESSAGE_{name.upper()}_H"


def _constructor(spec: MsgSpec, with_alloc: bool) -> list[str]:
    name = spec.short_name
    lines = [f"  {name}_({'const ContainerAllocator& _alloc' if with_alloc else ''})"]
    separator = ":"
    for f in spec.fields:
        if f.type.is_array:
            init = "_alloc" if f.type.array_len is None and with_alloc else ""
        elif with_alloc and f.type.base not in _NO_ALLOCATOR:
            init = "_alloc"
        else:
            init = _default(f.type.base)
        lines.append(f"    {separator} {f.name}({init})")
        separator = ","
    lines.append("  {")
    fixed = [f for f in spec.fields if f.type.is_array and f.type.array_len is not None]
    if with_alloc and not any(f.type.base == "string" for f in fixed):
        lines.append("  (void)_alloc;")
    for f in fixed:
        if with_alloc and f.type.base not in _NO_ALLOCATOR:
            lines.append(f"    {f.name}.assign({cpp_element_type(f.type.base)}(_alloc));")
        elif _default(f.type.base):
            lines.append(f"    {f.name}.assign({_default(f.type.base)});")
    lines.append("  }")
    return lines


def _constant_value(value: bool | int | float | str, type_: str) -> str:
    if type_ == "string":
        return f'"{escape(str(value))}"'
    if type_ == "bool":
        return str(int(bool(value)))
    return str(value)


def _printer_lines(spec: MsgSpec) -> list[str]:
    lines: list[str] = []
    for f in spec.fields:
        element = cpp_element_type(f.type.base)
        if f.type.is_array:
            lines += [
                f'    s << indent << "{f.name}[]" << std::endl;',
                f"    for (size_t i = 0; i < v.{f.name}.size(); ++i)",
                "    {",
                f'      s << indent << "  {f.name}[" << i << "]: ";',
            ]
            step = "  "
            if f.type.is_message:
                lines += ["      s << std::endl;", "      s << indent;"]
                step = "    "
            lines += [f'      Printer<{element}>::stream(s, indent + "{step}", v.{f.name}[i]);', "    }"]
        else:
            lines.append(f'    s << indent << "{f.name}: ";')
            if f.type.is_message:
                lines.append("    s << std::endl;")
            lines.append(f'    Printer<{element}>::stream(s, indent + "  ", v.{f.name});')
    return lines


def message_header(spec: MsgSpec, lookup: Lookup, md5sum: str, full_text: str, source: str = "") -> str:
    """``<pkg>/<Type>.h`` for one message (also a service's Request/Response and action messages).

    ``lookup`` resolves nested types (for IsFixedSize); ``source`` names the definition file in
    the header's first comment."""
    package, name = spec.package, spec.short_name
    full = f"::{package}::{name}_"
    with_alloc = f"{full}<ContainerAllocator>"
    guard = _guard(package, name)
    out = [
        f"// Generated by ninjemys from {source or spec.full_name}: do not edit.",
        f"#ifndef {guard}",
        f"#define {guard}",
        "",
        "#include <string>",
        "#include <vector>",
        "#include <memory>",
        "",
        "#include <ros/types.h>",
        "#include <ros/serialization.h>",
        "#include <ros/builtin_message_traits.h>",
        "#include <ros/message_operations.h>",
        "",
    ]
    out += [f"#include <{dep}.h>" for dep in spec.dependencies]
    out += ["", f"namespace {package}", "{", "template <class ContainerAllocator>", f"struct {name}_", "{"]
    out += [f"  typedef {name}_<ContainerAllocator> Type;", ""]
    out += _constructor(spec, with_alloc=False) + _constructor(spec, with_alloc=True) + [""]
    for f in spec.fields:
        out += [f"  typedef {cpp_field_type(f.type)} _{f.name}_type;", f"  _{f.name}_type {f.name};", ""]
    integers = [c for c in spec.constants if c.type in _SIGNED or c.type in _UNSIGNED]
    others = [c for c in spec.constants if c not in integers]
    if spec.constants:
        out.append("  // constant names that Windows.h may define as macros")
        for c in spec.constants:
            out += [f"#if defined(_WIN32) && defined({c.name})", f"  #undef {c.name}", "#endif"]
    if integers:
        out.append("  enum {")
        for c in integers:
            out.append(f"    {c.name} = {int(c.value)}{'u' if c.type in _UNSIGNED else ''},")
        out.append("  };")
    for c in others:
        out.append(f"  static const {CPP_BUILTINS[c.type]} {c.name};")
    out += [
        "",
        f"  typedef boost::shared_ptr< {with_alloc} > Ptr;",
        f"  typedef boost::shared_ptr< {with_alloc} const> ConstPtr;",
        "",
        f"}}; // struct {name}_",
        "",
        f"typedef {full}<std::allocator<void> > {name};",
        "",
        f"typedef boost::shared_ptr< ::{package}::{name} > {name}Ptr;",
        f"typedef boost::shared_ptr< ::{package}::{name} const> {name}ConstPtr;",
        "",
    ]
    for c in others:
        out += [
            f"template<typename ContainerAllocator> const {CPP_BUILTINS[c.type]}",
            f"  {name}_<ContainerAllocator>::{c.name} = {_constant_value(c.value, c.type)};",
        ]
    out += [
        "",
        "template<typename ContainerAllocator>",
        f"std::ostream& operator<<(std::ostream& s, const {with_alloc} & v)",
        "{",
        f'ros::message_operations::Printer< {with_alloc} >::stream(s, "", v);',
        "return s;",
        "}",
        "",
    ]
    if spec.fields:
        compare = " &&\n    ".join(f"lhs.{f.name} == rhs.{f.name}" for f in spec.fields)
        out += [
            "template<typename ContainerAllocator1, typename ContainerAllocator2>",
            f"bool operator==(const {full}<ContainerAllocator1> & lhs, const {full}<ContainerAllocator2> & rhs)",
            "{",
            f"  return {compare};",
            "}",
            "",
            "template<typename ContainerAllocator1, typename ContainerAllocator2>",
            f"bool operator!=(const {full}<ContainerAllocator1> & lhs, const {full}<ContainerAllocator2> & rhs)",
            "{",
            "  return !(lhs == rhs);",
            "}",
            "",
        ]
    out += [f"}} // namespace {package}", "", "namespace ros", "{", "namespace message_traits", "{", ""]
    for trait, value in (
        ("IsMessage", True),
        ("IsFixedSize", is_fixed_size(spec, lookup)),
        ("HasHeader", spec.has_header),
    ):
        kind = "TrueType" if value else "FalseType"
        for const in (" ", " const"):
            out += [
                "template <class ContainerAllocator>",
                f"struct {trait}< {with_alloc}{const}>",
                f"  : {kind}",
                "  { };",
                "",
            ]
    for trait, literal in (
        ("MD5Sum", f'"{md5sum}"'),
        ("DataType", f'"{spec.full_name}"'),
        ("Definition", definition_literal(full_text)),
    ):
        out += [
            "template<class ContainerAllocator>",
            f"struct {trait}< {with_alloc} >",
            "{",
            "  static const char* value()",
            "  {",
            f"    return {literal};",
            "  }",
            "",
            f"  static const char* value(const {with_alloc}&) {{ return value(); }}",
        ]
        if trait == "MD5Sum":
            out += [
                f"  static const uint64_t static_value1 = 0x{md5sum[:16]}ULL;",
                f"  static const uint64_t static_value2 = 0x{md5sum[16:]}ULL;",
            ]
        out += ["};", ""]
    out += ["} // namespace message_traits", "} // namespace ros", ""]
    out += ["namespace ros", "{", "namespace serialization", "{", ""]
    out.append(f"  template<class ContainerAllocator> struct Serializer< {with_alloc} >")
    out.append("  {")
    if spec.fields:
        out += [
            "    template<typename Stream, typename T> inline static void allInOne(Stream& stream, T m)",
            "    {",
        ]
        out += [f"      stream.next(m.{f.name});" for f in spec.fields]
        out.append("    }")
    else:
        out += ["    template<typename Stream, typename T> inline static void allInOne(Stream&, T)", "    {}"]
    out += ["", "    ROS_DECLARE_ALLINONE_SERIALIZER", f"  }}; // struct {name}_", ""]
    out += ["} // namespace serialization", "} // namespace ros", ""]
    out += ["namespace ros", "{", "namespace message_operations", "{", ""]
    out += ["template<class ContainerAllocator>", f"struct Printer< {with_alloc} >", "{"]
    if spec.fields:
        out.append(
            "  template<typename Stream> static void stream(Stream& s, const std::string& indent, "
            f"const {with_alloc}& v)"
        )
        out += ["  {", *_printer_lines(spec), "  }"]
    else:
        out += [
            f"  template<typename Stream> static void stream(Stream&, const std::string&, const {with_alloc}&)",
            "  {}",
        ]
    out += ["};", "", "} // namespace message_operations", "} // namespace ros", "", f"#endif // {guard}", ""]
    return "\n".join(out)


def service_header(spec: SrvSpec, md5sum: str, source: str = "") -> str:
    """``<pkg>/<Srv>.h``: the service struct and its traits; the Request and Response message
    headers (:func:`message_header` of ``spec.request`` / ``spec.response``) are included."""
    package, name = spec.package, spec.short_name
    full = f"::{package}::{name}"
    guard = _guard(package, name)
    out = [
        f"// Generated by ninjemys from {source or spec.full_name}: do not edit.",
        f"#ifndef {guard}",
        f"#define {guard}",
        "",
        "#include <ros/service_traits.h>",
        "",
        f"#include <{package}/{name}Request.h>",
        f"#include <{package}/{name}Response.h>",
        "",
        f"namespace {package}",
        "{",
        "",
        f"struct {name}",
        "{",
        "",
        f"typedef {spec.request.short_name} Request;",
        f"typedef {spec.response.short_name} Response;",
        "Request request;",
        "Response response;",
        "",
        "typedef Request RequestType;",
        "typedef Response ResponseType;",
        "",
        f"}}; // struct {name}",
        f"}} // namespace {package}",
        "",
        "namespace ros",
        "{",
        "namespace service_traits",
        "{",
        "",
    ]
    for trait, value in (("MD5Sum", md5sum), ("DataType", spec.full_name)):
        out += [
            "template<>",
            f"struct {trait}< {full} > {{",
            "  static const char* value()",
            "  {",
            f'    return "{value}";',
            "  }",
            "",
            f"  static const char* value(const {full}&) {{ return value(); }}",
            "};",
            "",
        ]
    for part in ("Request", "Response"):
        for trait in ("MD5Sum", "DataType"):
            out += [
                f"// the {part}'s service traits are the service's",
                "template<>",
                f"struct {trait}< {full}{part}>",
                "{",
                "  static const char* value()",
                "  {",
                f"    return {trait}< {full} >::value();",
                "  }",
                f"  static const char* value(const {full}{part}&)",
                "  {",
                "    return value();",
                "  }",
                "};",
                "",
            ]
    out += ["} // namespace service_traits", "} // namespace ros", "", f"#endif // {guard}", ""]
    return "\n".join(out)


__all__ = [
    "CPP_BUILTINS",
    "cpp_element_type",
    "cpp_field_type",
    "definition_literal",
    "escape",
    "is_fixed_size",
    "message_header",
    "service_header",
]

"""The ``.cfg`` parameter generator: ``gen = ParameterGenerator(); gen.add(...); gen.generate(...)``.

A ``.cfg`` file is a Python script written against ``dynamic_reconfigure.parameter_generator_catkin``.
Running it builds a group tree of parameter descriptions; :meth:`ParameterGenerator.generate` turns
that into the ``<pkg>.cfg.<Name>Config`` module a Server loads. ROS 1 runs the script from CMake with
four output paths on the command line; ninjemys' catkin_make runs it in-process (see
:func:`run_cfg`) and writes the module itself, so no CMake line is needed. The checks are ROS 1's
(names, types, min/max on str/bool, quotes in descriptions, enum types), plus duplicate names, which
in ROS 1 only show up as a C++ compile error.
"""

from __future__ import annotations

import math
import os
import re
import sys
import traceback
import types
from collections.abc import Callable
from pathlib import Path
from typing import Any

from ninjemys.errors import DefinitionError, NinjemysError

str_t = "str"
bool_t = "bool"
int_t = "int"
double_t = "double"

_PYTYPES: dict[str, Callable[[Any], object]] = {"str": str, "int": int, "double": float, "bool": bool}
_CTYPES = {"str": "std::string", "int": "int", "double": "double", "bool": "bool"}
_CCONST = {"str": "const char * const", "int": "const int", "double": "const double", "bool": "const bool"}
_MIN: dict[str, Any] = {"int": -0x80000000, "double": -math.inf, "str": "", "bool": False}
_MAX: dict[str, Any] = {"int": 0x7FFFFFFF, "double": math.inf, "str": "", "bool": True}
_DEFAULT: dict[str, Any] = {"int": 0, "double": 0.0, "str": "", "bool": False}
_NAME = re.compile(r"^[a-zA-Z][a-zA-Z0-9_]*$")
_HERE = os.path.normcase(os.path.abspath(__file__))


class CfgError(NinjemysError):
    """A mistake in a .cfg file; ``run_cfg`` turns it into ``file:line: reason``."""


def _caller() -> tuple[str, int]:
    """File (base name) and line of the first frame outside this module: the .cfg line being run."""
    frame: types.FrameType | None = sys._getframe(1)
    while frame is not None and os.path.normcase(os.path.abspath(frame.f_code.co_filename)) == _HERE:
        frame = frame.f_back
    if frame is None:
        return "", 0
    return os.path.basename(frame.f_code.co_filename), frame.f_lineno


def _check_description(text: str) -> None:
    if '"' in text or "'" in text:
        raise CfgError(f"quotes not allowed in description string `{text}`")


def _typed(param: dict[str, Any], key: str, fallback: Any) -> None:
    """Fill ``param[key]`` with ``fallback`` when None, else check it has the parameter's type."""
    value = param[key]
    if value is None:
        param[key] = fallback
        return
    kind = param["type"]
    want = _PYTYPES[kind]
    if type(value) is not want and not (want is float and type(value) is int):
        raise CfgError(f"'{param['name']}' has type {kind}, but {key} is {value!r}")
    param[key] = want(value)


class Group:
    """A group of parameters (``gen.add_group(name, type="", state=True)``); the root is ``Default``."""

    def __init__(self, gen: ParameterGenerator, name: str, type: str, state: bool, id: int, parent: int):
        self.gen = gen
        self.name = name.replace(" ", "_")
        self.type = type
        self.state = state
        self.id = id
        self.parent = parent
        self.groups: list[Group] = []
        self.parameters: list[dict[str, Any]] = []
        self.srcfile, self.srcline = _caller()
        gen._groups[id] = self

    def add_group(self, name: str, type: str = "", state: bool = True) -> _Group:
        group = Group(self.gen, name, type, state, self.gen._next_id, self.id)
        self.gen._next_id += 1
        self.groups.append(group)
        return group

    def add(
        self,
        name: str,
        paramtype: str,
        level: int,
        description: str,
        default: Any = None,
        min: Any = None,
        max: Any = None,
        edit_method: str = "",
    ) -> None:
        """Declare one parameter; ``level`` is the bit mask the server's callback receives on change."""
        srcfile, srcline = _caller()
        if paramtype not in _PYTYPES:
            raise CfgError(
                f"parameter '{name}' has unknown type {paramtype!r} (use int_t, double_t, str_t or bool_t)"
            )
        if paramtype in (str_t, bool_t) and (min is not None or max is not None):
            raise CfgError(f"Max or min specified for {name}, which is of '{paramtype}' type")
        if not isinstance(name, str) or not _NAME.match(name):
            raise CfgError(
                f"The name of field '{name}' does not follow the ROS naming conventions, "
                "see http://wiki.ros.org/ROS/Patterns/Conventions"
            )
        if type(level) is not int:
            raise CfgError(f"parameter '{name}': level must be an int, got {level!r}")
        if name in self.gen._names:
            raise CfgError(f"parameter '{name}' is already defined at line {self.gen._names[name]}")
        param: dict[str, Any] = {
            "name": name,
            "type": paramtype,
            "default": default,
            "level": level,
            "description": description,
            "min": min,
            "max": max,
            "srcline": srcline,
            "srcfile": srcfile,
            "edit_method": edit_method,
            "ctype": _CTYPES[paramtype],
            "cconsttype": _CCONST[paramtype],
        }
        _typed(param, "default", _DEFAULT[paramtype])
        _typed(param, "max", _MAX[paramtype])
        _typed(param, "min", _MIN[paramtype])
        self.gen._names[name] = srcline
        self.parameters.append(param)

    def _path(self) -> list[str]:
        if self.id == 0:
            return [self.name]
        return [*self.gen._groups[self.parent]._path(), self.name]

    def to_dict(self) -> dict[str, Any]:
        """The description dict ROS 1's generated modules carry as ``config_description``."""
        path = self._path()
        upper = [p.upper() for p in path]
        return {
            "name": self.name,
            "type": self.type,
            "state": self.state,
            "cstate": "true" if self.state else "false",
            "id": self.id,
            "parent": self.parent,
            "parameters": self.parameters,
            "groups": [g.to_dict() for g in self.groups],
            "srcline": self.srcline,
            "srcfile": self.srcfile,
            "class": "::".join(upper),
            "parentclass": "::".join(upper[:-1]),
            "parentname": self.gen._groups[self.parent].name,
            "field": "::".join([*upper[:-1], path[-1].lower()]),
            "upper": self.name.upper(),
            "lower": "groups" if self.id == 0 else self.name.lower(),
        }


# catkin_make installs a sink here while it runs a .cfg; generate() then hands its result over
# instead of writing files from command-line paths as under CMake.
_sink: Callable[[ParameterGenerator], None] | None = None


_Group = Group  # the class, under a name ParameterGenerator's class attribute ``Group`` does not hide


class ParameterGenerator:
    """``parameter_generator_catkin.ParameterGenerator``: the API every .cfg file is written against."""

    Group = Group

    def __init__(self) -> None:
        self._groups: dict[int, Group] = {}
        self._names: dict[str, int] = {}
        self._next_id = 1
        self.group = Group(self, "Default", "", True, 0, 0)
        self.constants: list[dict[str, Any]] = []
        self.pkgname = self.nodename = self.name = ""

    def const(self, name: str, type: str, value: Any, descr: str) -> dict[str, Any]:
        """A named constant for an enum (``gen.const("Low", int_t, 0, "slow")``); written as ``<Name>_<const>``."""
        srcfile, srcline = _caller()
        if type not in _PYTYPES:
            raise CfgError(f"constant '{name}' has unknown type {type!r}")
        _check_description(descr)
        const = {
            "name": name,
            "type": type,
            "value": value,
            "srcline": srcline,
            "srcfile": srcfile,
            "description": descr,
            "ctype": _CTYPES[type],
            "cconsttype": _CCONST[type],
        }
        if value is None:
            raise CfgError(f"constant '{name}' has no value")
        _typed(const, "value", None)
        self.constants.append(const)
        return const

    def enum(self, constants: list[dict[str, Any]], description: str) -> str:
        """An ``edit_method`` offering the given constants (what rqt_reconfigure shows as a drop-down)."""
        if len({c["type"] for c in constants}) != 1:
            raise CfgError("Inconsistent types in enum!")
        _check_description(description)
        return repr({"enum": constants, "enum_description": description})

    def add(
        self,
        name: str,
        paramtype: str,
        level: int,
        description: str,
        default: Any = None,
        min: Any = None,
        max: Any = None,
        edit_method: str = "",
    ) -> None:
        self.group.add(name, paramtype, level, description, default, min, max, edit_method)

    def add_group(self, name: str, type: str = "", state: bool = True) -> _Group:
        return self.group.add_group(name, type=type, state=state)

    def generate(self, pkgname: str, nodename: str, name: str) -> int:
        """Produce ``<pkgname>.cfg.<name>Config``; returns the exit status the .cfg passes to ``exit()``."""
        self.pkgname, self.nodename, self.name = pkgname, nodename, name
        if not isinstance(name, str) or not re.match(r"^[A-Za-z_][A-Za-z0-9_]*$", name):
            raise CfgError(f"generate(): config name {name!r} is not a valid Python identifier")
        for param in (p for g in self._groups.values() for p in g.parameters):
            if param["edit_method"]:
                _check_enum(param)
        if _sink is not None:
            _sink(self)
            return 0
        if len(sys.argv) < 5:
            raise SystemExit(
                "This .cfg file is a dynamic_reconfigure generator script: catkin_make runs it for you.\n"
                "To run it by hand: <file.cfg> <dynamic_reconfigure dir> <binary dir> <cpp dir> <python dir>"
            )
        out = Path(sys.argv[4]) / "cfg"
        out.mkdir(parents=True, exist_ok=True)
        (out / f"{name}Config.py").write_text(render_module(self), encoding="utf-8")
        (out / "__init__.py").touch()
        return 0


def _check_enum(param: dict[str, Any]) -> None:
    try:
        enum = eval(param["edit_method"], {"__builtins__": {}}, {})["enum"]  # our own repr() output
    except Exception:
        raise CfgError(
            f"parameter '{param['name']}': edit_method is not an enum made by gen.enum()"
        ) from None
    for const in enum:
        if const["type"] != param["type"]:
            raise CfgError(
                f"parameter '{param['name']}' has type {param['type']}, but its enum constant "
                f"'{const['name']}' has type {const['type']}"
            )


def render_module(gen: ParameterGenerator) -> str:
    """Python source of ``<Name>Config``: plain data plus the lookup tables a Server reads.

    It imports only ``dynamic_reconfigure.encoding.extract_params``, so the same file works with
    ninjemys' Server and with ROS 1's.
    """
    lines = [
        "# Generated by ninjemys catkin_make from a dynamic_reconfigure .cfg file. Do not edit.",
        f"# Package {gen.pkgname}, node {gen.nodename}, config {gen.name}.",
        "",
        "from dynamic_reconfigure.encoding import extract_params",
        "",
        "inf = float('inf')",
        "",
        f"config_description = {_literal(gen.group.to_dict())}",
        "",
        "min = {}",
        "max = {}",
        "defaults = {}",
        "level = {}",
        "type = {}",
        "all_level = 0",
        "",
        "for param in extract_params(config_description):",
        "    min[param['name']] = param['min']",
        "    max[param['name']] = param['max']",
        "    defaults[param['name']] = param['default']",
        "    level[param['name']] = param['level']",
        "    type[param['name']] = param['type']",
        "    all_level = all_level | param['level']",
        "",
    ]
    for const in gen.constants:
        lines.append(f"{gen.name}_{const['name']} = {const['value']!r}")
    return "\n".join(lines) + "\n"


def _literal(value: Any) -> str:
    """repr() that writes infinities as the module's ``inf`` name instead of the unparsable ``inf``."""
    if isinstance(value, float) and math.isinf(value):
        return "inf" if value > 0 else "-inf"
    if isinstance(value, dict):
        return "{" + ", ".join(f"{k!r}: {_literal(v)}" for k, v in value.items()) + "}"
    if isinstance(value, list):
        return "[" + ", ".join(_literal(v) for v in value) + "]"
    return repr(value)


def run_cfg(path: Path, package: str) -> list[ParameterGenerator]:
    """Run one .cfg script in-process and return the generators it passed to ``generate()``.

    Any mistake in it (a CfgError from the checks above, or any Python error in the script itself)
    becomes a DefinitionError ``path:line: reason`` naming the .cfg line that caused it.
    """
    global _sink
    results: list[ParameterGenerator] = []
    try:
        source = path.read_text(encoding="utf-8")
        code = compile(source, str(path), "exec")
    except OSError as exc:
        raise DefinitionError(f"cannot read: {exc.strerror}", str(path)) from None
    except SyntaxError as exc:
        raise DefinitionError(f"invalid Python: {exc.msg}", str(path), exc.lineno) from None
    saved_argv, saved_sink = sys.argv, _sink
    sys.argv = [str(path)]
    _sink = results.append
    namespace = {"__name__": "__main__", "__file__": str(path), "PACKAGE": package}
    try:
        exec(code, namespace)
    except SystemExit as exc:
        if exc.code not in (None, 0):
            raise DefinitionError(f"the script exited with status {exc.code}", str(path)) from None
    except Exception as exc:
        line = None
        for frame, lineno in traceback.walk_tb(exc.__traceback__):
            if frame.f_code.co_filename == str(path):
                line = lineno
        reason = str(exc) if isinstance(exc, CfgError) else f"{type(exc).__name__}: {exc}"
        raise DefinitionError(reason, str(path), line) from None
    finally:
        sys.argv, _sink = saved_argv, saved_sink
    if not results:
        raise DefinitionError(
            f'never calls gen.generate(PACKAGE, "node_name", "{path.stem}"), so it generates nothing',
            str(path),
        )
    return results

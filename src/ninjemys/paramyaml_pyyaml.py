"""PyYAML configured as ROS 1's rosparam: the loader and dumper behind :mod:`ninjemys.paramyaml`.

Kept apart so that importing :mod:`ninjemys.paramyaml` does not import PyYAML (~25 ms of every tool's
start-up); this module is imported on the first parse, or for a dump the built-in emitter
(:mod:`ninjemys.paramyaml_emit`) leaves to PyYAML.
"""

from __future__ import annotations

import math
import re
from typing import Any

import yaml

from ninjemys.paramyaml import ParamYamlError

_MATH = {k: v for k, v in vars(math).items() if not k.startswith("_")}
_DEGREES = re.compile(r"^deg\([^)]*\)$")
_RADIANS = re.compile(r"^rad\([^)]*\)$")


def _angle(text: str) -> float:
    if "__" in text:
        raise yaml.constructor.ConstructorError(None, None, f"invalid angle expression {text!r}")
    try:
        return float(eval(text, {"__builtins__": {}}, _MATH))  # noqa: S307 - math names only, no builtins
    except Exception as exc:
        raise yaml.constructor.ConstructorError(
            None, None, f"invalid angle expression {text!r}: {exc}"
        ) from None


def _strip_call(text: str, prefix: str) -> str:
    text = text.strip()
    return text[len(prefix) : -1] if text.startswith(prefix) and text.endswith(")") else text


class _Loader(yaml.SafeLoader):
    """SafeLoader with rosparam's angle tags and binary values."""


def _radians(loader: yaml.SafeLoader, node: yaml.ScalarNode) -> float:
    return _angle(_strip_call(str(loader.construct_scalar(node)), "rad("))


def _degrees(loader: yaml.SafeLoader, node: yaml.ScalarNode) -> float:
    return math.radians(_angle(_strip_call(str(loader.construct_scalar(node)), "deg(")))


_Loader.add_constructor("!radians", _radians)
_Loader.add_constructor("!degrees", _degrees)
_Loader.add_implicit_resolver("!radians", _RADIANS, ["r"])
_Loader.add_implicit_resolver("!degrees", _DEGREES, ["d"])


class _Dumper(yaml.SafeDumper):
    """Block style like ``yaml.dump``; ``bytes`` (XML-RPC base64 values) come out as ``!!binary``.

    ROS 1's rosparam registers its angle resolvers on PyYAML's dumper too, so a *string* such as
    ``deg(90)`` is printed quoted (and reads back as that string, not as an angle)."""


_Dumper.add_implicit_resolver("!radians", _RADIANS, list("rad("))
_Dumper.add_implicit_resolver("!degrees", _DEGREES, list("deg("))


def _wrap(exc: yaml.YAMLError) -> ParamYamlError:
    mark = getattr(exc, "problem_mark", None)
    problem = getattr(exc, "problem", None) or str(exc)
    if mark is not None:
        return ParamYamlError(f"{problem} (line {mark.line + 1}, column {mark.column + 1})")
    return ParamYamlError(str(problem))


def load(text: str) -> Any:
    """Parse one YAML value; raises ParamYamlError naming the line and column of a mistake."""
    try:
        return yaml.load(text, Loader=_Loader)  # noqa: S506 - a SafeLoader subclass
    except yaml.YAMLError as exc:
        raise _wrap(exc) from None


def load_all(text: str) -> list[Any]:
    """Parse every document of a (possibly multi-document) YAML file."""
    try:
        return list(yaml.load_all(text, Loader=_Loader))  # noqa: S506 - a SafeLoader subclass
    except yaml.YAMLError as exc:
        raise _wrap(exc) from None


def dump(value: Any) -> str:
    """What ``yaml.dump(value)`` prints in ROS 1's rosparam (sorted keys, non-ASCII escaped)."""
    return yaml.dump(value, Dumper=_Dumper, default_flow_style=False, allow_unicode=False)

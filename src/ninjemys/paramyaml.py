"""The YAML dialect of ROS parameters, shared by rosparam, roslaunch ``<rosparam>`` and ``_p:=v`` args.

It is YAML 1.1 (PyYAML's safe loader) plus what rosparam registers: ``!degrees``/``!radians`` tags,
implicit ``rad(pi/2)`` / ``deg(90)`` scalars, and ``!!binary`` values (``bytes``, sent as XML-RPC base64).
Dumping uses PyYAML's block style, as ``rosparam get/dump`` print.
"""

from __future__ import annotations

import math
import re
from typing import Any

import yaml

from ninjemys.errors import ParameterError

_MATH = {k: v for k, v in vars(math).items() if not k.startswith("_")}


class ParamYamlError(ParameterError):
    """YAML text that does not parse; the message carries the line and column of the mistake."""


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


def _radians(loader: yaml.SafeLoader, node: yaml.Node) -> float:
    return _angle(_strip_call(str(loader.construct_scalar(node)), "rad("))


def _degrees(loader: yaml.SafeLoader, node: yaml.Node) -> float:
    return math.radians(_angle(_strip_call(str(loader.construct_scalar(node)), "deg(")))


_Loader.add_constructor("!radians", _radians)
_Loader.add_constructor("!degrees", _degrees)
_Loader.add_implicit_resolver("!radians", re.compile(r"^rad\([^)]*\)$"), ["r"])
_Loader.add_implicit_resolver("!degrees", re.compile(r"^deg\([^)]*\)$"), ["d"])


class _Dumper(yaml.SafeDumper):
    """Block-style dumper; ``bytes`` (XML-RPC base64 values) come out as ``!!binary``."""


def _wrap(exc: yaml.YAMLError) -> ParamYamlError:
    mark = getattr(exc, "problem_mark", None)
    problem = getattr(exc, "problem", None) or str(exc)
    if mark is not None:
        return ParamYamlError(f"{problem} (line {mark.line + 1}, column {mark.column + 1})")
    return ParamYamlError(str(problem))


def load_yaml(text: str) -> Any:
    """Parse one YAML value; raises ParamYamlError naming the line and column of a mistake."""
    try:
        return yaml.load(text, Loader=_Loader)  # noqa: S506 - a SafeLoader subclass
    except yaml.YAMLError as exc:
        raise _wrap(exc) from None


def load_yaml_documents(text: str) -> list[Any]:
    """Parse every document of a (possibly multi-document) YAML file."""
    try:
        return list(yaml.load_all(text, Loader=_Loader))  # noqa: S506 - a SafeLoader subclass
    except yaml.YAMLError as exc:
        raise _wrap(exc) from None


def dump_yaml(value: Any) -> str:
    """Block-style YAML as rosparam prints it (keys sorted, unicode kept)."""
    return yaml.dump(value, Dumper=_Dumper, default_flow_style=False, allow_unicode=True)

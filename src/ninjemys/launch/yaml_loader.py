"""YAML for ``<rosparam>``: safe loading plus rosparam's ``!degrees`` and ``!radians`` tags."""

from __future__ import annotations

import math
from typing import Any

import yaml

_MATH = {k: v for k, v in vars(math).items() if not k.startswith("_")}


def _angle_expression(text: str) -> float:
    if "__" in text:
        raise yaml.constructor.ConstructorError(None, None, f"invalid angle expression {text!r}")
    try:
        return float(eval(text, {"__builtins__": {}}, _MATH))  # noqa: S307 - math names only, no builtins
    except Exception as exc:
        raise yaml.constructor.ConstructorError(
            None, None, f"invalid angle expression {text!r}: {exc}"
        ) from None


class _Loader(yaml.SafeLoader):
    """SafeLoader with the two angle tags rosparam registers."""


def _radians(loader: yaml.SafeLoader, node: yaml.Node) -> float:
    return _angle_expression(str(loader.construct_scalar(node)))


def _degrees(loader: yaml.SafeLoader, node: yaml.Node) -> float:
    return math.radians(_angle_expression(str(loader.construct_scalar(node))))


_Loader.add_constructor("!radians", _radians)
_Loader.add_constructor("!degrees", _degrees)


def load_yaml(text: str) -> Any:
    """Parse rosparam YAML text (raises yaml.YAMLError on bad input)."""
    return yaml.load(text, Loader=_Loader)  # noqa: S506 - a SafeLoader subclass

"""Parameter value conversion as roslaunch does it (``type="auto|str|int|double|bool|yaml"``)."""

from __future__ import annotations

from typing import Any

from ninjemys.errors import LaunchError


def convert_value(value: str, type_: str) -> Any:
    """Convert launch-file text to a parameter value.

    ``auto``: a number with ``.`` is a double, digits (without ``_``) an int, ``true``/``false``
    (any case) a bool, anything else stays a string.
    """
    type_ = type_.lower().strip()
    if type_ == "auto":
        try:
            if "." in value:
                return float(value)
            if "_" not in value:
                return int(value)
        except ValueError:
            pass
        if value.lower() in ("true", "false"):
            return value.lower() == "true"
        return value
    if type_ in ("str", "string"):
        return value
    try:
        if type_ == "int":
            return int(value)
        if type_ == "double":
            return float(value)
    except ValueError:
        raise LaunchError(f"{value!r} is not a '{type_}' value") from None
    if type_ in ("bool", "boolean"):
        low = value.lower().strip()
        if low in ("true", "1"):
            return True
        if low in ("false", "0"):
            return False
        raise LaunchError(f"{value} is not a '{type_}' type")
    if type_ == "yaml":
        from ninjemys.paramyaml import ParamYamlError, load_yaml

        try:
            return load_yaml(value)
        except ParamYamlError as exc:
            raise LaunchError(f"invalid YAML value: {exc}") from None
    raise LaunchError(f"Unknown type '{type_}'")

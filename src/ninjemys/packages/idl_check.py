"""Build-time validation of msg/srv/action files through the IDL parser (``ninjemys.idl.parser``).

Kept behind one function so catkin_make does not depend on the parser's internal layout: the
parser's errors (DefinitionError with file:line) propagate unchanged.
"""

from __future__ import annotations

import importlib
from pathlib import Path

from ninjemys.errors import DefinitionError


def validate(path: Path, package: str, kind: str) -> None:
    """Parse one definition file; DefinitionError (file:line) when it is malformed."""
    try:
        text = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise DefinitionError(f"cannot read definition: {exc}", path=str(path)) from None
    try:
        parser = importlib.import_module("ninjemys.idl.parser")
    except ModuleNotFoundError:
        return
    full_name = f"{package}/{path.stem}"
    func = getattr(parser, f"parse_{kind}", None)
    if func is None:
        return
    try:
        func(text, full_name, path=str(path))
    except DefinitionError as exc:
        if exc.path is None:
            raise DefinitionError(exc.reason, path=str(path), line=exc.line) from None
        raise

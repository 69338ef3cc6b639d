"""Build-time validation of msg/srv/action files through the IDL parser (``ninjemys.idl.parser``).

Kept behind one function so catkin_make has one place that knows the parser's entry point; the
parser's DefinitionError (``file:line: what``) propagates unchanged.
"""

from __future__ import annotations

from pathlib import Path

from ninjemys.idl.parser import parse_file
from ninjemys.idl.spec import ActionSpec, MsgSpec, SrvSpec


def validate(path: Path, package: str) -> MsgSpec | SrvSpec | ActionSpec:
    """Parse one definition file; DefinitionError (file:line) when it is malformed."""
    return parse_file(path, package)

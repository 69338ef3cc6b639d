"""Build-time check that every message field type names a message that exists (catkin_make).

genmsg fails ``catkin_make`` when a field's type cannot be found (``Cannot locate message [String] in
package [pkg]``); the parser alone cannot see it, because a bare type resolves into the file's own
package (``String date`` in ``pkg/msg/time_msg.msg`` means ``pkg/String``). This module compares
the types a definition uses with the messages the workspace, its underlays, ROS_PACKAGE_PATH and
ninjemys define, and names the first missing one with ``file:line`` and, when another package has a
message of that name, the spelling that was probably meant (``std_msgs/String``).
"""

from __future__ import annotations

from collections.abc import Callable, Iterable
from pathlib import Path

from ninjemys.errors import DefinitionError
from ninjemys.idl.parser import ACTION_SUFFIXES
from ninjemys.idl.spec import BUILTIN_TYPES, ActionSpec, MsgSpec, SrvSpec

#: (type as resolved, type as written) of one field, e.g. ("pkg/String", "String[]")
Reference = tuple[str, str]


def references(spec: MsgSpec | SrvSpec | ActionSpec) -> list[Reference]:
    """The message types a parsed definition's fields use (builtins excluded), each once."""
    if isinstance(spec, SrvSpec):
        parts = [spec.request, spec.response]
    elif isinstance(spec, ActionSpec):
        parts = [spec.goal, spec.result, spec.feedback]  # what the user wrote, not the generated seven
    else:
        parts = [spec]
    found: dict[str, str] = {}
    for part in parts:
        for field in part.fields:
            if field.type.base not in BUILTIN_TYPES:
                found.setdefault(field.type.base, field.raw_type)
    return sorted(found.items())


def package_messages(package_dir: Path) -> set[str]:
    """Short names of the messages a package defines: its msg/*.msg and each action's seven."""
    names = {p.stem for p in (package_dir / "msg").glob("*.msg")}
    for action in (package_dir / "action").glob("*.action"):
        names.update(action.stem + suffix for suffix in ACTION_SUFFIXES)
    return names


def check(
    uses: Iterable[tuple[Path, str, list[Reference]]],
    package_dir: Callable[[str], Path | None],
) -> None:
    """Raise DefinitionError (``file:line``) for the first field type no package defines.

    ``uses`` holds (definition file, its package, its references); ``package_dir`` finds a package
    by name (None when it is nowhere).
    """
    known: dict[str, set[str] | None] = {}

    def messages(package: str) -> set[str] | None:
        if package not in known:
            where = package_dir(package)
            known[package] = None if where is None else package_messages(where)
        return known[package]

    for path, owner, refs in uses:
        for full, written in refs:
            package, _, short = full.partition("/")
            names = messages(package)
            if names is not None and short in names:
                continue
            if names is None:
                why = f"package '{package}' is not in the workspace, on ROS_PACKAGE_PATH nor shipped with ninjemys"
            else:
                why = f"package '{package}' has no message '{short}'"
            hint = _suggest(short, package, messages) if "/" not in written else ""
            raise DefinitionError(
                f"{owner}/{path.stem}: field type '{written}' cannot be resolved: {why}{hint}",
                str(path),
                _line_of(path, written),
            )


#: packages whose messages a bare name most likely meant, looked at for the hint
_COMMON = ("std_msgs", "geometry_msgs", "sensor_msgs", "nav_msgs", "actionlib_msgs", "visualization_msgs")


def _suggest(short: str, package: str, messages: Callable[[str], set[str] | None]) -> str:
    for candidate in _COMMON:
        if candidate != package and short in (messages(candidate) or ()):
            return f" (did you mean '{candidate}/{short}'?)"
    return ""


def _line_of(path: Path, written: str) -> int | None:
    """The line declaring a field of type ``written`` (the parser keeps no line per field)."""
    try:
        lines = path.read_text(encoding="utf-8").splitlines()
    except (OSError, UnicodeDecodeError):
        return None
    for number, line in enumerate(lines, 1):
        tokens = line.split("#", 1)[0].split()
        if tokens and tokens[0] == written:
            return number
    return None

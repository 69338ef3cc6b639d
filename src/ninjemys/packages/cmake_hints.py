"""Reading the few facts catkin_make needs from a package's CMakeLists.txt, without CMake.

ninjemys builds pure-Python packages, so CMakeLists.txt is never executed; it is only read for
``catkin_python_setup()`` and ``catkin_install_python(PROGRAMS ... DESTINATION ...)``. The
message-generation calls the tutorials teach (``add_message_files``, ``generate_messages``) are
accepted but not needed: every msg/srv/action file of a package is generated regardless.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

_COMMENT = re.compile(r"#[^\n]*")
_CALL = re.compile(r"\b([A-Za-z_][A-Za-z0-9_]*)\s*\(([^()]*)\)", re.S)


@dataclass(frozen=True)
class CMakeHints:
    python_setup: bool = False
    install_programs: tuple[str, ...] = ()


def read_cmake_hints(package_dir: Path) -> CMakeHints:
    """What CMakeLists.txt says about Python setup and installed scripts (missing file: nothing)."""
    path = package_dir / "CMakeLists.txt"
    try:
        text = _COMMENT.sub("", path.read_text(encoding="utf-8", errors="replace"))
    except OSError:
        return CMakeHints()
    python_setup = False
    programs: list[str] = []
    for match in _CALL.finditer(text):
        command = match.group(1).lower()
        args = match.group(2).split()
        if command == "catkin_python_setup":
            python_setup = True
        elif command == "catkin_install_python" and args and args[0] == "PROGRAMS":
            for arg in args[1:]:
                if arg == "DESTINATION":
                    break
                if "${" not in arg:
                    programs.append(arg.strip("\"'"))
    return CMakeHints(python_setup=python_setup, install_programs=tuple(programs))

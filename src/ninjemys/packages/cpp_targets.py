"""The C++ targets a package's CMakeLists.txt declares, which ninjemys' catkin_make does not build.

catkin_make here never runs CMake or a compiler, so ``add_executable`` / ``add_library`` targets are
skipped; saying so (with where each is declared and what it would have compiled) beats a
``rosrun`` that later cannot find the program. Only the calls are read, as CMake would see them:
comments are ignored and ``${PROJECT_NAME}`` is the package name.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

_COMMENT = re.compile(r"#[^\n]*")
_TARGET = re.compile(r"\b(add_executable|add_library)\s*\(([^()]*)\)", re.IGNORECASE | re.S)
#: add_library / add_executable keywords that are not sources
_KEYWORDS = frozenset({"STATIC", "SHARED", "MODULE", "OBJECT", "INTERFACE", "IMPORTED", "ALIAS", "GLOBAL"})
_KEYWORDS |= {"WIN32", "MACOSX_BUNDLE", "EXCLUDE_FROM_ALL"}


@dataclass(frozen=True)
class CppTarget:
    """One compiled target: its kind (``add_executable``), name, sources and declaring line."""

    command: str
    name: str
    sources: tuple[str, ...]
    path: Path
    line: int

    def describe(self) -> str:
        sources = ", ".join(self.sources) or "no sources listed"
        return f"{self.path}:{self.line}: {self.command}({self.name}) ({sources})"


def cpp_targets(package_dir: Path, package: str) -> list[CppTarget]:
    """Every add_executable / add_library of the package's CMakeLists.txt (none if it has none)."""
    path = package_dir / "CMakeLists.txt"
    try:
        text = path.read_text(encoding="utf-8", errors="replace")
    except OSError:
        return []
    # blank the comments but keep every offset, so line numbers stay right
    text = _COMMENT.sub(lambda m: " " * len(m.group(0)), text)
    targets = []
    for match in _TARGET.finditer(text):
        args = [a.strip("\"'").replace("${PROJECT_NAME}", package) for a in match.group(2).split()]
        if not args:
            continue
        sources = tuple(a for a in args[1:] if a not in _KEYWORDS)
        if "IMPORTED" in args or "ALIAS" in args or "INTERFACE" in args:
            continue  # nothing to compile
        line = text.count("\n", 0, match.start()) + 1
        targets.append(CppTarget(match.group(1).lower(), args[0], sources, path, line))
    return targets


def skipped_message(package: str, targets: list[CppTarget], toolchain: bool = False) -> list[str]:
    """The lines catkin_make prints for a package's C++ targets; ``toolchain``: the C++ build ran
    but could not build them (a dependency's C++ side is missing), so the advice differs."""
    if not targets:
        return []
    advice = (
        "install the C++ side named below, then run catkin_make again"
        if toolchain
        else "ninjemys builds Python packages, without CMake or a compiler; port them to Python, "
        "or build them with ROS 1's catkin"
    )
    lines = [f"-- ~~  - {package}: {len(targets)} C++ target(s) not built ({advice}):"]
    lines += [f"--        {t.describe()}" for t in targets]
    return lines


__all__ = ["CppTarget", "cpp_targets", "skipped_message"]

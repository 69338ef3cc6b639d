"""Reading the few facts catkin_make needs from a package's CMakeLists.txt, without CMake.

ninjemys builds pure-Python packages, so CMakeLists.txt is never executed; it is only read for
``catkin_python_setup()``, ``catkin_install_python(PROGRAMS ... DESTINATION ...)`` and the
``find_package(... REQUIRED ...)`` calls: those are where real catkin fails on a missing package
(a dependency named only in package.xml never fails a catkin build). The message-generation calls
the tutorials teach (``add_message_files``, ``generate_messages``) are accepted but not needed:
every msg/srv/action file of a package is generated regardless.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

_COMMENT = re.compile(r"#[^\n]*")
_CALL = re.compile(r"\b([A-Za-z_][A-Za-z0-9_]*)\s*\(([^()]*)\)", re.S)


@dataclass(frozen=True)
class Requirement:
    """One package a ``find_package(... REQUIRED ...)`` call must find; ``catkin`` is True for a
    component of ``find_package(catkin REQUIRED COMPONENTS ...)`` (catkinConfig.cmake finds it)."""

    name: str
    line: int
    catkin: bool


@dataclass(frozen=True)
class CMakeHints:
    python_setup: bool = False
    install_programs: tuple[tuple[str, str], ...] = ()
    required: tuple[Requirement, ...] = ()
    #: the .test files of ``add_rostest(file ...)``, relative to the package (``catkin_make run_tests``)
    rostests: tuple[str, ...] = ()
    #: ``catkin_add_nosetests(path [WORKING_DIRECTORY dir])``: (path, dir or None, line), in file order
    nosetests: tuple[tuple[str, str | None, int], ...] = ()
    #: the CMakeLists.txt line of each ``catkin_install_python`` program, for error messages
    program_lines: tuple[tuple[str, int], ...] = ()
    #: ``roslint_cpp(files)`` / ``roslint_python(files)``: ("cpp" or "python", files as written, line)
    lint: tuple[tuple[str, tuple[str, ...], int], ...] = ()
    #: ``set(ROSLINT_CPP_OPTS ...)`` / ``set(ROSLINT_PYTHON_OPTS ...)``: ("cpp" or "python", options)
    lint_opts: tuple[tuple[str, tuple[str, ...]], ...] = ()

    @property
    def programs(self) -> tuple[str, ...]:
        return tuple(program for program, _ in self.install_programs)

    def missing_program(self, package_dir: Path, program: str) -> str:
        """catkin's words for a ``catkin_install_python`` program that does not exist, with the place."""
        line = dict(self.program_lines).get(program)
        where = f"{package_dir / 'CMakeLists.txt'}" + (f":{line}" if line else "")
        return f"{where}: catkin_install_python() called with non-existing file '{package_dir / program}'."


def read_cmake_hints(package_dir: Path) -> CMakeHints:
    """What CMakeLists.txt says about Python setup and installed scripts (missing file: nothing)."""
    path = package_dir / "CMakeLists.txt"
    try:
        text = _COMMENT.sub("", path.read_text(encoding="utf-8", errors="replace"))
    except OSError:
        return CMakeHints()
    python_setup = False
    programs: list[tuple[str, str]] = []
    required: list[Requirement] = []
    rostests: list[str] = []
    nosetests: list[tuple[str, str | None, int]] = []
    program_lines: list[tuple[str, int]] = []
    lint: list[tuple[str, tuple[str, ...], int]] = []
    lint_opts: dict[str, tuple[str, ...]] = {}
    for match in _CALL.finditer(text):
        command = match.group(1).lower()
        args = [a.strip("\"'") for a in match.group(2).split()]
        line = text.count("\n", 0, match.start()) + 1
        if command == "catkin_python_setup":
            python_setup = True
        elif command == "catkin_install_python" and args and args[0] == "PROGRAMS":
            destination = _destination(args)
            for arg in args[1:]:
                if arg == "DESTINATION":
                    break
                if "${" not in arg:
                    programs.append((arg, destination))
                    program_lines.append((arg, line))
        elif command == "find_package" and args:
            required.extend(_requirements(args, line))
        elif command == "add_rostest" and args and "${" not in args[0]:
            rostests.append(args[0])
        elif command in ("roslint_cpp", "roslint_python"):
            lint.append((command.removeprefix("roslint_"), tuple(args), line))
        elif command == "set" and args and args[0] in ("ROSLINT_CPP_OPTS", "ROSLINT_PYTHON_OPTS"):
            options = [o for a in args[1:] for o in a.split(";") if o]
            lint_opts[args[0].split("_")[1].lower()] = tuple(options)
        elif command == "catkin_add_nosetests" and args:
            workdir = args[args.index("WORKING_DIRECTORY") + 1] if "WORKING_DIRECTORY" in args[:-1] else None
            nosetests.append((args[0], workdir, line))
    return CMakeHints(
        python_setup=python_setup,
        install_programs=tuple(programs),
        required=tuple(required),
        rostests=tuple(rostests),
        nosetests=tuple(nosetests),
        program_lines=tuple(program_lines),
        lint=tuple(lint),
        lint_opts=tuple(lint_opts.items()),
    )


def _destination(args: list[str]) -> str:
    """Where catkin_install_python puts a program in the devel space, relative to devel/:
    ``lib/<pkg>`` for CATKIN_PACKAGE_BIN_DESTINATION (the default), ``share/<pkg>/dir`` for
    ``${CATKIN_PACKAGE_SHARE_DESTINATION}/dir`` and so on ("{pkg}" stands for the package name)."""
    if "DESTINATION" not in args or args.index("DESTINATION") + 1 >= len(args):
        return "lib/{pkg}"
    value = args[args.index("DESTINATION") + 1]
    for variable, prefix in _DESTINATIONS.items():
        value = value.replace("${" + variable + "}", prefix)
    return value.strip("/") or "lib/{pkg}"


#: catkin's destination variables, as devel-space paths (catkin_destinations.cmake)
_DESTINATIONS = {
    "CATKIN_PACKAGE_BIN_DESTINATION": "lib/{pkg}",
    "CATKIN_PACKAGE_SHARE_DESTINATION": "share/{pkg}",
    "CATKIN_PACKAGE_LIB_DESTINATION": "lib",
    "CATKIN_PACKAGE_PYTHON_DESTINATION": "lib/python3/dist-packages/{pkg}",
    "CATKIN_GLOBAL_BIN_DESTINATION": "bin",
    "CATKIN_GLOBAL_SHARE_DESTINATION": "share",
    "CATKIN_GLOBAL_LIB_DESTINATION": "lib",
    "CATKIN_GLOBAL_PYTHON_DESTINATION": "lib/python3/dist-packages",
}

_FIND_PACKAGE_KEYWORDS = frozenset(
    {
        "EXACT",
        "QUIET",
        "MODULE",
        "CONFIG",
        "NO_MODULE",
        "REQUIRED",
        "COMPONENTS",
        "OPTIONAL_COMPONENTS",
        "NO_POLICY_SCOPE",
        "GLOBAL",
        "NAMES",
        "CONFIGS",
        "HINTS",
        "PATHS",
        "PATH_SUFFIXES",
    }
)


def _requirements(args: list[str], line: int) -> list[Requirement]:
    """The packages one find_package call requires (none unless REQUIRED; variables are skipped)."""
    if "REQUIRED" not in args or "${" in args[0]:
        return []
    if args[0] != "catkin":
        return [Requirement(args[0], line, catkin=False)]
    names: list[Requirement] = []
    collecting = False
    for arg in args[1:]:
        if arg in ("COMPONENTS", "REQUIRED"):  # components may follow REQUIRED without the keyword
            collecting = True
        elif arg in _FIND_PACKAGE_KEYWORDS:
            collecting = False
        elif collecting and "${" not in arg:
            names.append(Requirement(arg, line, catkin=True))
    return names

"""``catkin_make roslint`` / ``catkin_make roslint_<pkg>``: the lint targets roslint's CMake functions make.

In ROS 1, ``roslint_cpp()`` and ``roslint_python()`` in a package's CMakeLists.txt add commands to the
make target ``roslint_<pkg>`` (and ``roslint`` runs every package's); a lint error fails the make
and catkin_make with it. ninjemys' catkin_make reads those calls (:mod:`ninjemys.packages.cmake_hints`)
and runs the same linters (:mod:`ninjemys.tools.roslint`) in the package directory, with the
package's ``ROSLINT_CPP_OPTS``/``ROSLINT_PYTHON_OPTS``, whether or not the package has C++ targets.
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

from ninjemys.errors import PackageError
from ninjemys.packages.cmake_hints import read_cmake_hints
from ninjemys.packages.workspace import Workspace

_GLOBS = {"cpp": ("*.cpp", "*.h", "*.hpp"), "python": ("*.py",)}
_LINTER = {"cpp": "cpplint", "python": "pep8"}


def is_lint_target(target: str) -> bool:
    """Whether a catkin_make target is one of roslint's."""
    return target == "roslint" or target.startswith("roslint_")


def _files(package: Path, name: str, kind: str, written: tuple[str, ...], line: int) -> list[str]:
    """The files one call lints: those it names (relative to the package), or every matching file."""
    if not written:
        return sorted(str(p) for pattern in _GLOBS[kind] for p in package.rglob(pattern) if p.is_file())
    files: list[str] = []
    for arg in written:
        value = arg
        for variable in ("PROJECT_SOURCE_DIR", "CMAKE_CURRENT_SOURCE_DIR"):
            value = value.replace("${" + variable + "}", str(package))
        value = value.replace("${PROJECT_NAME}", name)
        if "${" in value:
            raise PackageError(
                f"{package / 'CMakeLists.txt'}:{line}: roslint_{kind}({' '.join(written)}): ninjemys' "
                f"catkin_make does not run CMake here and cannot expand '{arg}'; name the files, or call "
                f"roslint_{kind}() without arguments to lint every {'/'.join(_GLOBS[kind])} of the package"
            )
        files.append(value)
    return files


def run_lint_target(ws: Workspace, target: str) -> int:
    """Run one lint target; 0 when every linter passed. A target no package makes is make's error."""
    lints = {p.name: (p.path, read_cmake_hints(p.path)) for p in ws.packages}
    lints = {name: entry for name, entry in lints.items() if entry[1].lint}
    if target == "roslint":
        chosen = sorted(lints)
    else:
        chosen = [target.removeprefix("roslint_")] if target.removeprefix("roslint_") in lints else []
    if not chosen:
        print(f"make: *** No rule to make target '{target}'.  Stop.", file=sys.stderr)
        print(f'Invoking "make {target}" failed', file=sys.stderr)
        return 1
    failed = False
    for name in chosen:
        package, hints = lints[name]
        options = dict(hints.lint_opts)
        for kind, written, line in hints.lint:
            files = _files(package, name, kind, written, line)
            if not files:
                print("CMake Warning: roslint: no files provided for command", file=sys.stderr)
                continue
            command = [
                sys.executable,
                "-m",
                "ninjemys.tools.roslint",
                _LINTER[kind],
                *options.get(kind, ()),
                *files,
            ]
            print(f"-- roslint_{name}: {_LINTER[kind]} on {len(files)} file(s)", flush=True)
            failed |= subprocess.run(command, cwd=package).returncode != 0
        if failed:
            print(f"make[3]: *** [roslint_{name}] Error 1", file=sys.stderr)
            break
    if failed:
        print(f'Invoking "make {target}" failed', file=sys.stderr)
        return 1
    print(f"[100%] Built target {target}")
    return 0

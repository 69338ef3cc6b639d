"""Process entry point for shipped executables: ``python -m ninjemys.packages.run_shipped PKG EXE args``.

Imports the module named in :mod:`ninjemys.packages.shipped`, sets ``sys.argv`` as the node expects
(``[EXE, *prefix_args, *args]``) and calls its function. A module that is not installed is reported
in one line (which executable, which module), never with a traceback.
"""

from __future__ import annotations

import importlib
import inspect
import sys
from collections.abc import Mapping

from ninjemys.commands import answer_sigint
from ninjemys.packages.shipped import shipped_executable


def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    answer_sigint()
    if len(argv) < 2:
        print(
            "ERROR: usage: python -m ninjemys.packages.run_shipped PACKAGE EXECUTABLE [args...]",
            file=sys.stderr,
        )
        return 2
    package, name, args = argv[0], argv[1], argv[2:]
    exe = shipped_executable(package, name)
    if exe is None:
        print(f"ERROR: ninjemys ships no executable [{name}] in package [{package}]", file=sys.stderr)
        return 1
    try:
        module = importlib.import_module(exe.module)
    except KeyboardInterrupt:  # Ctrl-C while the node was still importing: it ends quietly, as below
        return 0
    except ModuleNotFoundError as exc:
        if exc.name and exe.module.startswith(exc.name):
            print(
                f"ERROR: {package}/{name} needs module {exe.module}, which is not installed in this ninjemys",
                file=sys.stderr,
            )
            return 1
        raise
    function = getattr(module, exe.function, None)
    if function is None:
        print(
            f"ERROR: {package}/{name}: module {exe.module} has no function {exe.function}()", file=sys.stderr
        )
        return 1
    full_args = [*exe.prefix_args, *args]
    sys.argv = [name, *full_args]
    params: Mapping[str, inspect.Parameter]
    try:
        params = inspect.signature(function).parameters
    except (TypeError, ValueError):
        params = {}
    try:
        result = function(full_args) if params else function()
    except KeyboardInterrupt:
        return 0
    return result if isinstance(result, int) else 0


if __name__ == "__main__":
    sys.exit(main())

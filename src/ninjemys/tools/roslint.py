"""roslint's linters: ``rosrun roslint cpplint`` / ``pep8`` and what ``roslint_cpp()``/``roslint_python()`` run.

ROS 1's roslint bundles Google's cpplint and pycodestyle, set to the ROS style guides instead of
Google's: lines up to 120 columns, ``{`` and ``}`` on lines of their own, header guards named after
the path under ``include/`` (``MY_PKG_FOO_H``), no rule on include order or streams, no complaint about
access labels or non-const references. ninjemys runs the released linters (the ``cpplint`` and
``pycodestyle`` packages on PyPI, which roslint's copies come from) with those rules, so a package
whose CMakeLists.txt calls ``roslint_cpp()`` gets the same kind of report from ``catkin_make
roslint_<pkg>``. The brace rule is ours, written from the ROS C++ style guide.

``python -m ninjemys.tools.roslint cpplint|pep8 ARGS`` is the form the CMake functions use;
``junit RESULTS CMD...`` runs a lint command and writes its outcome as one JUnit test case
(``roslint_add_test()`` under ``catkin_make run_tests``).
"""

from __future__ import annotations

import os
import re
import subprocess
import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any
from xml.sax.saxutils import escape, quoteattr

from ninjemys.commands import entry

#: the ROS style guides' line length (C++ and Python)
LINE_LENGTH = 120
#: Google rules the ROS C++ style guide does not have
_SILENCED = frozenset(
    {"build/include_order", "build/include_alpha", "readability/streams", "readability/braces"}
)
_OPEN_ALONE = "when starting a new scope, { should be on a line by itself"
_CLOSE_ALONE = "} should be on a line by itself"
_CPP_FILTER = "--filter=-runtime/references"

ErrorFn = Callable[[str, int, str, int, str], None]


def ros_header_guard(filename: str) -> str:
    """The guard the ROS style wants: the path below ``include/`` (or below the package, the
    directory holding package.xml), upper case, with ``_`` for ``/ . -`` and spaces."""
    parts: list[str] = []
    head = os.path.abspath(filename)
    while True:
        head, tail = os.path.split(head)
        if not tail:
            break
        parts.insert(0, tail)
        if head.endswith("include") or os.path.exists(os.path.join(head, "package.xml")):
            break
    return re.sub(r"[-./\s]", "_", "_".join(parts)).upper()


def ros_braces(filename: str, clean_lines: Any, linenum: int, error: ErrorFn) -> None:
    """Braces of the ROS C++ style: a ``{`` opening a scope and a ``}`` closing one stand alone on
    their line; both on one line (a one-line body, an initializer row) and ``};`` are fine, and so is
    ``... = {`` / ``) {`` after an ``=`` (an initializer)."""
    line = clean_lines.elided[linenum]
    if re.match(r"^(.*)\{(.*)\}.*$", line):
        return
    opening = re.match(r"^(.*)\{(.*)$", line)
    if opening and opening.group(1).strip():
        if not ("=" in line and re.search(r"(=|\))\s*\{\s*$", line)):
            error(filename, linenum, "whitespace/braces", 4, _OPEN_ALONE)
    closing = re.match(r"^(.*)\}(.*)$", line)
    if closing and (closing.group(1).strip() or closing.group(2).strip()) and closing.group(2).strip() != ";":
        error(filename, linenum, "whitespace/braces", 4, _CLOSE_ALONE)


def _ros_errors(original: ErrorFn) -> ErrorFn:
    def report(filename: str, linenum: int, category: str, confidence: int, message: str) -> None:
        if category in _SILENCED:
            return
        if category == "whitespace/braces" and message not in (_OPEN_ALONE, _CLOSE_ALONE):
            return  # Google's brace placement; the ROS one is ros_braces
        if "should be indented +1 space inside" in message:
            return
        original(filename, linenum, category, confidence, message)

    return report


def cpplint_main(argv: list[str]) -> int:
    """cpplint with the ROS C++ rules; its report and exit status (1 when it found errors)."""
    import cpplint  # type: ignore[import-untyped]

    cpplint.Error = _ros_errors(cpplint.Error)
    cpplint.CheckBraces = ros_braces
    cpplint.GetHeaderGuardCPPVariable = ros_header_guard
    return _run_main(cpplint.main, ["cpplint", f"--linelength={LINE_LENGTH}", _CPP_FILTER, *argv])


def pep8_main(argv: list[str]) -> int:
    """pycodestyle (the renamed pep8) at the ROS line length; its report and exit status."""
    import pycodestyle  # type: ignore[import-untyped]

    return _run_main(pycodestyle._main, ["pep8", f"--max-line-length={LINE_LENGTH}", *argv])


def _run_main(function: Callable[[], object], argv: list[str]) -> int:
    saved = sys.argv
    sys.argv = argv
    try:
        function()
    except SystemExit as exc:
        return exc.code if isinstance(exc.code, int) else (0 if exc.code is None else 1)
    finally:
        sys.argv = saved
    return 0


def junit_main(argv: list[str]) -> int:
    """``junit RESULTS CMD...``: run the lint command, echo its output, and write RESULTS as one test
    case named after the command's last word (the target), failed when the command failed."""
    if len(argv) < 2:
        print("usage: python -m ninjemys.tools.roslint junit RESULTS_FILE COMMAND...", file=sys.stderr)
        return 2
    results, command = Path(argv[0]), argv[1:]
    run = subprocess.run(command, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    sys.stderr.write(run.stdout)
    name = quoteattr(command[-1])
    if run.returncode == 0:
        body = f'  <testcase name={name} status="run" classname="roslint.LintCheck"/>\n'
    else:
        body = (
            f'  <testcase name={name} classname="roslint.LintCheck">\n'
            '    <failure message="One or more linter errors was reported." type="">'
            f"{escape(run.stdout)}</failure>\n  </testcase>\n"
        )
    results.parent.mkdir(parents=True, exist_ok=True)
    failures = 0 if run.returncode == 0 else 1
    results.write_text(
        '<?xml version="1.0" encoding="UTF-8"?>\n'
        f'<testsuite name="roslint" tests="1" failures="{failures}" errors="0">\n{body}</testsuite>\n',
        encoding="utf-8",
    )
    return 0 if run.returncode == 0 else 1


_LINTERS: dict[str, Callable[[list[str]], int]] = {
    "cpplint": cpplint_main,
    "pep8": pep8_main,
    "pycodestyle": pep8_main,
    "junit": junit_main,
}


def main(argv: list[str] | None = None) -> int:
    """``python -m ninjemys.tools.roslint LINTER ARGS``."""
    args = sys.argv[1:] if argv is None else argv
    if not args or args[0] not in _LINTERS:
        print(f"usage: python -m ninjemys.tools.roslint {{{','.join(_LINTERS)}}} ARGS...", file=sys.stderr)
        return 2
    return _LINTERS[args[0]](args[1:])


console_main = entry(main)

if __name__ == "__main__":
    sys.exit(console_main())

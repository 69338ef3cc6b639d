"""``catkin_make``: build the workspace in the current directory (pure Python; no CMake, no compiler).

Accepts the usual catkin_make options so habits and scripts keep working: ``-C DIR``,
``--source``, ``--build``, ``-j N``/``-lN``, ``-DVAR=VALUE`` and make targets are accepted (targets
other than ``clean`` and the CMake options have nothing to do in a pure-Python build).
"""

from __future__ import annotations

import argparse
import os
import time

from ninjemys.packages.builder import build_workspace, clean_workspace
from ninjemys.packages.workspace import Workspace
from ninjemys.tools.cli import entry


def _parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(
        prog="catkin_make", description="Builds a catkin workspace (ninjemys, pure Python)"
    )
    p.add_argument("-C", "--directory", default=".", help="The base path of the workspace (default '.')")
    p.add_argument("--source", help="The path to the source space (default 'workspace_base/src')")
    p.add_argument("--build", help="The path to the build space (default 'workspace_base/build')")
    p.add_argument("--use-ninja", action="store_true", help="accepted for compatibility")
    p.add_argument("--use-nmake", action="store_true", help="accepted for compatibility")
    p.add_argument("--force-cmake", action="store_true", help="accepted for compatibility")
    p.add_argument("--pkg", nargs="+", help="accepted: every package is always generated")
    p.add_argument("--only-pkg-with-deps", nargs="+", help="accepted: every package is always generated")
    p.add_argument("--cmake-args", nargs=argparse.REMAINDER, default=[], help="accepted for compatibility")
    p.add_argument("--make-args", nargs=argparse.REMAINDER, default=[], help="accepted for compatibility")
    p.add_argument("-j", "--jobs", help="accepted for compatibility")
    p.add_argument("targets", nargs="*", help="make targets: 'clean' removes build/ and devel/")
    return p


def main(argv: list[str] | None = None) -> int:
    argv = list(argv or [])
    passthrough = [a for a in argv if a.startswith(("-D", "-l")) and len(a) > 2]
    args = _parser().parse_args([a for a in argv if a not in passthrough])
    ws = Workspace.at(args.directory, source=args.source, build=args.build)
    print(f"Base path: {ws.root}")
    print(f"Source space: {ws.source}")
    print(f"Build space: {ws.build}")
    print(f"Devel space: {ws.devel}")
    if "clean" in args.targets:
        clean_workspace(ws)
        print("####\n#### Removed build and devel spaces\n####")
        return 0
    start = time.monotonic()
    print("-- ~~  traversing packages in topological order:")
    report = build_workspace(ws, env=os.environ, log=print)
    elapsed = time.monotonic() - start
    print(
        f"[100%] Built target(s) {' '.join(report.packages) or '(none)'}: "
        f"{len(report.written)} file(s) updated, {report.validated} definition(s) checked, {elapsed:.2f}s"
    )
    if report.cpp_skipped:
        names = ", ".join(t.name for t in report.cpp_skipped)
        print(f"-- {len(report.cpp_skipped)} C++ target(s) not built (see above): {names}")
    return 0


console_main = entry(main)

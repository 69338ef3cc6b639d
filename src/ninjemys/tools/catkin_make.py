"""``catkin_make``: build the workspace in the current directory (pure Python; no CMake, no compiler).

Accepts the usual catkin_make options so habits and scripts keep working: ``-C DIR``,
``--source``, ``--build``, ``-j N``/``-lN``, ``-DVAR=VALUE`` and make targets are accepted (targets
other than ``clean`` and ``install`` and the CMake options other than ``CMAKE_INSTALL_PREFIX`` have
nothing to do in a pure-Python build).
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import time
from pathlib import Path

from ninjemys.commands import command_path
from ninjemys.packages.builder import build_workspace, clean_workspace
from ninjemys.packages.cmake_hints import read_cmake_hints
from ninjemys.packages.cpp_build import install_cpp
from ninjemys.packages.install_space import install_workspace
from ninjemys.packages.workspace import Workspace
from ninjemys.rostest.junit import CaseResult, SuiteResult, write_xml
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
    p.add_argument(
        "targets",
        nargs="*",
        help="make targets: 'clean' removes build/ and devel/; 'install' also writes the install space; "
        "'run_tests' runs the add_rostest() files with rostest",
    )
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
    prefix = _install_prefix(ws, passthrough)
    report = build_workspace(ws, env=os.environ, log=print, install_prefix=prefix)
    elapsed = time.monotonic() - start
    print(
        f"[100%] Built target(s) {' '.join(report.packages) or '(none)'}: "
        f"{len(report.written)} file(s) updated, {report.validated} definition(s) checked, {elapsed:.2f}s"
    )
    for package, programs in report.cpp_built.items():
        print(f"-- {package}: C++ program(s) built by catkin's CMake: {' '.join(p.name for p in programs)}")
    if report.cpp_skipped:
        names = ", ".join(t.name for t in report.cpp_skipped)
        print(f"-- {len(report.cpp_skipped)} C++ target(s) not built (see above): {names}")
    if "install" in args.targets:
        _install(ws, prefix, report.cpp_build)
    if "run_tests" in args.targets:
        _run_tests(ws)
    return 0


def _run_tests(ws: Workspace) -> None:
    """``catkin_make run_tests``: every ``add_rostest(file)`` of the workspace, through ``rostest``
    with the devel space on the paths. As with catkin, a failing test does not fail catkin_make:
    the results go where catkin puts them, ``build/test_results/<pkg>/rostest-<file>.xml``, for
    ``catkin_test_results`` (``catkin_make run_tests && catkin_test_results`` is the CI idiom; with
    the results elsewhere it would report 0 tests and pass). A test that writes no result leaves a
    ``MISSING-`` failure file there, as catkin's run_tests.py does."""
    env = dict(os.environ)
    for key, value in (
        ("ROS_PACKAGE_PATH", str(ws.source)),
        ("PYTHONPATH", str(ws.devel / "lib" / "python3" / "dist-packages")),
        ("CMAKE_PREFIX_PATH", str(ws.devel)),
    ):
        env[key] = os.pathsep.join([value, *([env[key]] if env.get(key) else [])])
    rostest = command_path("rostest")
    results_dir = ws.build / "test_results"
    for pkg in ws.ordered():
        for test_file in read_cmake_hints(pkg.path).rostests:
            path = pkg.path / test_file
            print(f"-- run_tests_{pkg.name}_rostest_{test_file.replace('/', '_')}", flush=True)
            if not path.is_file():
                print(f"-- {pkg.path / 'CMakeLists.txt'}: add_rostest({test_file}) names a missing file")
                continue
            # catkin's add_rostest: the results file is named after the path without its extensions
            stem = test_file.replace("/", "_").split(".")[0]
            results = results_dir / pkg.name / f"rostest-{stem}.xml"
            for old in (results, results.with_name(f"MISSING-{results.name}")):
                old.unlink(missing_ok=True)
            subprocess.run(
                [
                    rostest,
                    "--pkgdir",
                    str(pkg.path),
                    "--package",
                    pkg.name,
                    "--results-filename",
                    f"{stem}.xml",
                    "--results-base-dir",
                    str(results_dir),
                    str(path),
                ],
                env=env,
                check=False,
            )
            if not results.is_file():
                _write_missing_result(results, f"run_tests_{pkg.name}_rostest_{test_file.replace('/', '_')}")


def _write_missing_result(results: Path, target: str) -> None:
    """A failing JUnit file beside the expected one: ``catkin_test_results`` counts it as a failure."""
    missing = results.with_name(f"MISSING-{results.name}")
    print(f"Cannot find results, writing failure results to '{missing}'", file=sys.stderr)
    write_xml(
        missing,
        SuiteResult(
            name=results.stem,
            cases=[
                CaseResult(
                    classname="Results",
                    name="test_ran",
                    failure=f"{target}: the test did not write its result file {results}",
                )
            ],
        ),
    )


def _install_prefix(ws: Workspace, cmake_args: list[str]) -> Path:
    """CMAKE_INSTALL_PREFIX: ``-DCMAKE_INSTALL_PREFIX[:PATH]=dir`` (relative to the workspace), by
    default ``install/`` next to ``devel/``."""
    prefix = ws.root / "install"
    for arg in cmake_args:
        name, _, value = arg[2:].partition("=")
        if name.split(":", 1)[0] == "CMAKE_INSTALL_PREFIX" and value:
            prefix = ws.root / Path(value).expanduser()
    return prefix.resolve()


def _install(ws: Workspace, prefix: Path, cpp_build: Path | None) -> None:
    """``catkin_make install``: after the build, the install space. The C++ packages' own install
    rules (``install(TARGETS ...)`` & co) run first through catkin's CMake, where a toolchain built
    them; ninjemys' install of the Python side and the setup scripts follows."""
    count = install_cpp(cpp_build, log=print) if cpp_build is not None else 0
    count += install_workspace(ws, prefix, os.environ, log=print)
    print(f"[100%] Installed {count} file(s) in {prefix}: source {prefix / 'setup.bash'} to use them")


console_main = entry(main)

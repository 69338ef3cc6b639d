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
from ninjemys.errors import PackageError
from ninjemys.packages.builder import build_workspace, clean_workspace
from ninjemys.packages.cmake_hints import read_cmake_hints
from ninjemys.packages.cpp_build import install_cpp
from ninjemys.packages.install_space import install_workspace
from ninjemys.packages.workspace import Workspace
from ninjemys.rostest.junit import CaseResult, SuiteResult, write_xml
from ninjemys.tools.catkin_roslint import is_lint_target, run_lint_target
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
        "'run_tests' runs the add_rostest() files with rostest and the catkin_add_nosetests() tests; "
        "'roslint' / 'roslint_<pkg>' run the linters of roslint_cpp() and roslint_python()",
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
    if _testing_enabled(passthrough):
        _check_nosetests_paths(ws)
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
    for target in (t for t in args.targets if is_lint_target(t)):
        if run_lint_target(ws, target) != 0:
            return 1
    if "run_tests" in args.targets:
        if _testing_enabled(passthrough):
            _run_tests(ws, _results_dir(ws, passthrough))
        else:
            print("-- Skipping the tests: enable testing via -DCATKIN_ENABLE_TESTING (catkin's words)")
    return 0


def _run_tests(ws: Workspace, results_dir: Path) -> None:
    """``catkin_make run_tests``: every ``add_rostest(file)`` and ``catkin_add_nosetests(path)`` of the
    workspace, with the devel space on the paths. As with catkin, a failing test does not fail
    catkin_make: the results go where catkin puts them, ``<results>/<pkg>/rostest-<file>.xml`` and
    ``nosetests-<path>.xml`` (``<results>`` is ``build/test_results`` or ``-DCATKIN_TEST_RESULTS_DIR``),
    for ``catkin_test_results`` (``catkin_make run_tests && catkin_test_results`` is the CI idiom;
    with the results elsewhere it would report 0 tests and pass). Each package's old result files
    are removed first, as catkin's clean_test_results target does. A test that writes no result
    leaves a ``MISSING-`` failure file there, as catkin's run_tests.py does."""
    env = dict(os.environ)
    for key, value in (
        ("ROS_PACKAGE_PATH", str(ws.source)),
        ("PYTHONPATH", str(ws.devel / "lib" / "python3" / "dist-packages")),
        ("CMAKE_PREFIX_PATH", str(ws.devel)),
    ):
        env[key] = os.pathsep.join([value, *([env[key]] if env.get(key) else [])])
    for pkg in ws.ordered():
        hints = read_cmake_hints(pkg.path)
        if not hints.rostests and not hints.nosetests:
            continue
        _clean_results(results_dir / pkg.name)
        for test_file in hints.rostests:
            _run_rostest(pkg.name, pkg.path, test_file, results_dir, env)
        for test_path, workdir, _line in hints.nosetests:
            _run_nosetests(ws, pkg.name, pkg.path, test_path, workdir, results_dir, env)


def _cmake_define(cmake_args: list[str], variable: str) -> str | None:
    """The value of the last ``-DVARIABLE[:TYPE]=value`` among the arguments (None if none sets it):
    on CMake's command line, as in its cache, the last definition wins."""
    found = None
    for arg in cmake_args:
        name, _, value = arg[2:].partition("=")
        if arg.startswith("-D") and name.split(":", 1)[0] == variable:
            found = value
    return found


def _testing_enabled(cmake_args: list[str]) -> bool:
    """catkin's CATKIN_ENABLE_TESTING (on unless ``-DCATKIN_ENABLE_TESTING=OFF``/0/FALSE/NO)."""
    value = _cmake_define(cmake_args, "CATKIN_ENABLE_TESTING")
    return value is None or value.strip().upper() not in ("OFF", "0", "FALSE", "NO", "N", "")


def _check_nosetests_paths(ws: Workspace) -> None:
    """catkin's configure step: a ``catkin_add_nosetests`` path that does not exist stops the build
    (``Can't find nosetests path``), before anything is built, whatever the target."""
    ws.load()
    for pkg in ws.packages:
        for test_path, _workdir, line in read_cmake_hints(pkg.path).nosetests:
            text = _package_vars(test_path, pkg.path)
            if "${" in text or (pkg.path / text).exists():
                continue
            where = f"{pkg.path.relative_to(ws.source)}/CMakeLists.txt:{line}"
            raise PackageError(
                "CMake Error at /usr/share/catkin/cmake/test/nosetests.cmake:54 (message):\n"
                f"  Can't find nosetests path '{test_path}'\nCall Stack (most recent call first):\n"
                f"  {where} (catkin_add_nosetests)"
            )


def _clean_results(package_results: Path) -> None:
    """catkin's ``clean_test_results_<pkg>``: every ``.xml`` below the package's results directory."""
    print(f"Removing test result files from '{package_results}'")
    if not package_results.is_dir():
        return
    for path in sorted(package_results.rglob("*.xml")):
        if not any(part.startswith(".") for part in path.relative_to(package_results).parts[:-1]):
            print(f"- removing '{path}'")
            path.unlink()


def _run_rostest(name: str, pkg_dir: Path, test_file: str, results_dir: Path, env: dict[str, str]) -> None:
    target = f"run_tests_{name}_rostest_{test_file.replace('/', '_')}"
    print(f"-- {target}", flush=True)
    path = pkg_dir / test_file
    if not path.is_file():
        print(f"-- {pkg_dir / 'CMakeLists.txt'}: add_rostest({test_file}) names a missing file")
        return
    # catkin's add_rostest: the results file is named after the path without its extensions
    stem = test_file.replace("/", "_").split(".")[0]
    results = results_dir / name / f"rostest-{stem}.xml"
    results.with_name(f"MISSING-{results.name}").unlink(missing_ok=True)
    subprocess.run(
        [
            command_path("rostest"),
            "--pkgdir",
            str(pkg_dir),
            "--package",
            name,
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
        _write_missing_result(results, target)


def _run_nosetests(
    ws: Workspace,
    name: str,
    pkg_dir: Path,
    test_path: str,
    workdir: str | None,
    results_dir: Path,
    env: dict[str, str],
) -> None:
    """One ``catkin_add_nosetests``: nose's collection by :mod:`ninjemys.rostest.nose`, in the
    package's build directory (or WORKING_DIRECTORY), the file named as catkin names it."""
    path_text, workdir = _package_vars(test_path, pkg_dir), workdir and _package_vars(workdir, pkg_dir)
    output = path_text
    for prefix in (str(pkg_dir), str(ws.build / name)):
        if output == prefix or output == prefix + "/":
            output = ""
        elif output.startswith(prefix + "/"):
            output = output[len(prefix) + 1 :]
    output = (output or ".").replace("/", ".").replace(":", ".")
    target = f"run_tests_{name}_nosetests_{output}"
    print(f"-- {target}", flush=True)
    path = pkg_dir / path_text
    if "${" in path_text:
        print(
            f"-- {pkg_dir / 'CMakeLists.txt'}: nosetests path '{test_path}' names a CMake variable ninjemys does not know"
        )
        return
    results = results_dir / name / f"nosetests-{output}.xml"
    cwd = Path(workdir) if workdir and "${" not in workdir else ws.build / name
    cwd = cwd if cwd.is_absolute() else pkg_dir / cwd
    cwd.mkdir(parents=True, exist_ok=True)
    results.with_name(f"MISSING-{results.name}").unlink(missing_ok=True)
    subprocess.run(
        [sys.executable, "-m", "ninjemys.rostest.nose", str(path), "--xunit-file", str(results)],
        env=env,
        cwd=cwd,
        check=False,
    )
    if not results.is_file():
        _write_missing_result(results, target)


def _package_vars(text: str, pkg_dir: Path) -> str:
    """The package-directory variables catkin_add_nosetests paths use, replaced."""
    for var in ("PROJECT_SOURCE_DIR", "CMAKE_CURRENT_SOURCE_DIR", "CMAKE_CURRENT_LIST_DIR"):
        text = text.replace("${" + var + "}", str(pkg_dir))
    return text


def _results_dir(ws: Workspace, cmake_args: list[str]) -> Path:
    """``-DCATKIN_TEST_RESULTS_DIR=dir`` (relative: to the build space, where CMake runs), by default
    ``build/test_results``."""
    value = _cmake_define(cmake_args, "CATKIN_TEST_RESULTS_DIR")
    chosen = ws.build / Path(value).expanduser() if value else ws.build / "test_results"
    return chosen.resolve()


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
    value = _cmake_define(cmake_args, "CMAKE_INSTALL_PREFIX")
    prefix = ws.root / Path(value).expanduser() if value else ws.root / "install"
    return prefix.resolve()


def _install(ws: Workspace, prefix: Path, cpp_build: Path | None) -> None:
    """``catkin_make install``: after the build, the install space. The C++ packages' own install
    rules (``install(TARGETS ...)`` & co) run first through catkin's CMake, where a toolchain built
    them; ninjemys' install of the Python side and the setup scripts follows."""
    count = install_cpp(cpp_build, log=print) if cpp_build is not None else 0
    count += install_workspace(ws, prefix, os.environ, log=print)
    print(f"[100%] Installed {count} file(s) in {prefix}: source {prefix / 'setup.bash'} to use them")


console_main = entry(main)

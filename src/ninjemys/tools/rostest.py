"""``rostest``: run a package's integration tests from a ``.test`` launch file, as ROS 1 does.

``rostest pkg file.test [arg:=value ...]`` (or ``rostest path/file.test``) starts a master of its
own on a free port (``--reuse-master``: the one at ROS_MASTER_URI), loads the file's parameters,
starts its ``<node>``s through roslaunch, then runs each ``<test>`` node in turn with
``--gtest_output=xml:<results file>``, within its ``time-limit`` (default 60 s) and ``retry``
count. Each test's JUnit XML is gathered into ``~/.ros/test_results/<pkg>/rostest-<file>.xml``;
the exit status is 0 only when every test case passed.
"""

from __future__ import annotations

import argparse
import os
import signal
import socket
import subprocess
import sys
from dataclasses import dataclass, replace
from pathlib import Path

from ninjemys.commands import command_path, entry
from ninjemys.errors import LaunchError, NinjemysError
from ninjemys.launch import master_link
from ninjemys.launch.launcher import LaunchOptions, process_specs
from ninjemys.launch.plan import LaunchPlan, NodeSpec
from ninjemys.launch.xml import load_launch
from ninjemys.master.client import MasterClient
from ninjemys.net.addresses import free_port
from ninjemys.packages.discovery import PackageIndex
from ninjemys.packages.executables import find_executable
from ninjemys.roshome import log_directory
from ninjemys.rostest.junit import (
    XML_OUTPUT_FLAG,
    CaseResult,
    SuiteResult,
    TestResultsError,
    read_xml,
    results_file,
    write_xml,
)
from ninjemys.tools.roslaunch import resolve_files

DEFAULT_TIME_LIMIT = 60.0


def _parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="rostest", usage="usage: rostest [options] [package] <filename>", add_help=True
    )
    parser.add_argument(
        "-t", "--text", action="store_true", help="Run with stdout output instead of XML output"
    )
    parser.add_argument("--pkgdir", metavar="PKG_DIR", help="package dir")
    parser.add_argument("--package", metavar="PACKAGE", help="package")
    parser.add_argument("--results-filename", metavar="RESULTS_FILENAME", help="results_filename")
    parser.add_argument(
        "--results-base-dir", metavar="RESULTS_BASE_DIR", help="The base directory of the test results."
    )
    parser.add_argument(
        "-r",
        "--reuse-master",
        action="store_true",
        help="Connect to an existing ROS master instead of spawning a new ROS master on a custom port",
    )
    parser.add_argument(
        "-c",
        "--clear",
        action="store_true",
        help="Clear all parameters when connecting to an existing ROS master (only works with --reuse-master)",
    )
    parser.add_argument("positional", nargs="*")
    return parser


def _owning_package(path: Path) -> tuple[str, Path] | None:
    """(name, directory) of the package whose package.xml is at or above ``path``."""
    from ninjemys.packages.manifest import parse_manifest

    for directory in path.resolve().parents:
        if (directory / "package.xml").is_file():
            return parse_manifest(directory / "package.xml").name, directory
    return None


def _test_file_name(pkg_dir: Path | None, test_file: Path) -> str:
    """The file's package-relative path, ``/`` as ``_``, without extension (rostest's naming)."""
    absolute = test_file.resolve()
    rel = (
        str(absolute.relative_to(pkg_dir))
        if pkg_dir is not None and absolute.is_relative_to(pkg_dir)
        else absolute.name
    )
    name = rel.replace(os.sep, "_")
    return name[: name.rfind(".")] if "." in name else name


def _stop(proc: subprocess.Popen[bytes], grace: float = 10.0) -> None:
    """SIGINT the process group, then SIGKILL it if it lingers."""
    if proc.poll() is not None:
        return
    try:
        os.killpg(proc.pid, signal.SIGINT)
        proc.wait(timeout=grace)
    except (ProcessLookupError, subprocess.TimeoutExpired):
        try:
            os.killpg(proc.pid, signal.SIGKILL)
        except ProcessLookupError:
            pass
        proc.wait()


@dataclass
class TestRun:
    """One ``<test>`` node's run: the cases its results file reports, and rostest's own verdict on
    running it (``ok``; ``failure`` when it left no results; ``error`` when it overran its time)."""

    name: str
    cases: list[CaseResult]
    verdict: str = "ok"
    why: str = ""


def _unrunnable(test: NodeSpec, index: PackageIndex) -> str | None:
    """rostest's words for a ``<test>`` whose package or executable cannot be found (a test file
    without ``chmod +x`` is the usual case): that test fails and the others still run."""
    try:
        manifest = index.find(test.package)
    except NinjemysError:
        return f"Package [{test.package}] for test node [{test.package}/{test.type}] does not exist"
    try:
        find_executable(manifest, test.type)
    except NinjemysError:
        return f"Test node [{test.package}/{test.type}] does not exist or is not executable"
    return None


def _run_test(
    test: NodeSpec, plan: LaunchPlan, package: str, uri: str, log_dir: Path, env: dict[str, str], text: bool
) -> TestRun:
    """Run one ``<test>`` node, again while it fails and retries are left."""
    name = test.test_name or test.name or test.type
    unrunnable = _unrunnable(test, PackageIndex.from_environment())
    if unrunnable is not None:
        return TestRun(name, [], "failure", unrunnable)
    target = results_file(package, name, env=env)
    limit = test.time_limit if test.time_limit is not None else DEFAULT_TIME_LIMIT
    attempts = 1 + max(0, test.retry or 0)
    run = TestRun(name, [])
    for attempt in range(attempts):
        if target.exists():
            target.unlink()
        spec = process_specs(replace(plan, nodes=[test], tests=[]), LaunchOptions(), uri, log_dir, env)[0]
        argv = [*spec.argv, *(["--text"] if text else []), f"{XML_OUTPUT_FLAG}{target}"]
        # as in ROS 1, a test node's output goes to its log file; --text shows it
        out_path = log_dir / f"{spec.name}-stdout.log"
        with open(out_path, "ab") as out:
            sink = None if text else out
            proc = subprocess.Popen(
                argv, env=spec.env, cwd=spec.cwd, stdout=sink, stderr=sink, start_new_session=True
            )
            try:
                proc.wait(timeout=limit)
                timed_out = False
            except subprocess.TimeoutExpired:
                timed_out = True
                _stop(proc, 5.0)
        if timed_out:
            why = f"max time [{limit}s] allotted for test [{name}] of type [{test.package}/{test.type}]"
            run = TestRun(name, [], "error", why)
        elif text:
            run = TestRun(name, [])  # ROS 1 does not read results in --text mode
        elif not target.exists():
            run = TestRun(name, [], "failure", f"test [{name}] did not generate test results")
        else:
            try:
                run = TestRun(name, read_xml(target).cases)
            except TestResultsError as exc:
                run = TestRun(name, [], "failure", str(exc))
        if run.verdict == "ok" and all(c.passed for c in run.cases):
            break
        if attempt + 1 < attempts:
            print(f"[ROSTEST] test [{name}] failed, retrying ({attempt + 1} of {attempts - 1})", flush=True)
    return run


def _description(test_id: str, case: CaseResult) -> str:
    """rosunit's line(s) for a case: ``[id/name][passed]``, or the FAILURE/ERROR block."""
    if case.passed:
        return f"[{test_id}/{case.name}][passed]\n"
    out = ""
    for label, text in (("FAILURE", case.failure), ("ERROR", case.error)):
        if text is not None:
            head = f"[{test_id}/{case.name}][{label}]"
            out += head + "-" * (80 - len(head)) + f"\n{text.strip()}\n" + "-" * 80 + "\n\n"
    return out


def _report(package: str, runs: list[TestRun], log_file: Path) -> str:
    """rostest's closing report (the [ROSTEST] block and SUMMARY), as Debian's prints it."""
    out = "\n[ROSTEST]" + "-" * 71 + "\n\n"
    cases = [case for run in runs for case in run.cases]
    for run in runs:
        for case in run.cases:
            out += _description(f"{package}.rosunit-{run.name}", case)
    for run in runs:
        if run.verdict == "failure":
            out += f"[test{run.name}][failed]\n"
    errors = sum(c.error is not None for c in cases) + sum(r.verdict == "error" for r in runs)
    failures = sum(c.failure is not None for c in cases) + sum(r.verdict == "failure" for r in runs)
    red = "\033[1;31m"
    out += "\nSUMMARY\n"
    out += (
        "\033[32m * RESULT: SUCCESS\033[0m\n"
        if not errors and not failures
        else f"{red} * RESULT: FAIL\033[0m\n"
    )
    out += f" * TESTS: {len(cases)}\n"
    out += f"{red} * ERRORS: {errors}\033[0m\n" if errors else " * ERRORS: 0\n"
    out += f"{red} * FAILURES: {failures}\033[0m\n" if failures else " * FAILURES: 0\n"
    not_run = [run.name for run in runs if run.verdict == "failure"]
    if not_run:
        out += "\nERROR: The following tests failed to run:\n" + "".join(f" * test{n}\n" for n in not_run)
    return out + f"\nrostest log file is in {log_file}"


def main(argv: list[str] | None = None) -> int:
    opts = _parser().parse_args(sys.argv[1:] if argv is None else argv)
    if opts.clear and not opts.reuse_master:
        print("The --clear option is only valid with --reuse-master", file=sys.stderr)
        return 1
    files, launch_args, rosrun_form = resolve_files(opts.positional)
    if rosrun_form is not None or len(files) != 1 or files == ["-"]:
        raise LaunchError("rostest: give one .test file: rostest [package] <file.test> [arg:=value ...]")
    test_file = Path(files[0])
    owner = _owning_package(test_file)
    package = opts.package or (owner[0] if owner else "")
    if not package:
        raise LaunchError(f"{test_file}: not inside a package (no package.xml above it): give --package")
    pkg_dir = Path(opts.pkgdir) if opts.pkgdir else (owner[1] if owner else None)
    plan = load_launch([str(test_file)], argv=launch_args)
    env = dict(os.environ)
    if opts.results_base_dir:
        env["ROS_TEST_RESULTS_DIR"] = opts.results_base_dir
    log_root = log_directory(env)
    log_file = log_root / f"rostest-{socket.gethostname()}-{os.getpid()}.log"
    core: subprocess.Popen[bytes] | None = None
    nodes: subprocess.Popen[bytes] | None = None
    if opts.reuse_master:
        uri = master_link.master_uri_for(None, env)
        if not master_link.master_is_up(uri):
            raise LaunchError(f"--reuse-master: no master at {uri}")
    else:
        uri = f"http://localhost:{free_port()}/"
        core = master_link.start_core(uri, log_root / "rostest-master.log", env)
    env["ROS_MASTER_URI"] = uri
    try:
        client = MasterClient(uri, "/rostest")
        if opts.clear:
            for key in client.get_param_names():
                if key != "/run_id":
                    client.delete_param(key)
        log_dir = log_root / master_link.run_id(client)
        log_dir.mkdir(parents=True, exist_ok=True)
        master_link.load_parameters(client, plan)
        client.close()
        if plan.nodes:
            launch = [command_path("roslaunch"), "--no-summary", str(test_file), *launch_args]
            nodes = subprocess.Popen(launch, env=env, stdin=subprocess.DEVNULL, start_new_session=True)
        suite_name = _test_file_name(pkg_dir, test_file)
        if opts.results_filename:
            # a name, not a path (catkin's add_rostest passes one): its stem names the results, which
            # go to <results dir>/<pkg>/rostest-<stem>.xml like every other rostest result
            name = opts.results_filename
            suite_name = name[: name.rfind(".")] if "." in name else name
        combined = str(results_file(package, suite_name, is_rostest=True, env=env))
        print(f"... logging to {log_file}", flush=True)
        print(f"[ROSUNIT] Outputting test results to {combined}", flush=True)
        runs: list[TestRun] = []
        # rostest makes each <test> a method test<test-name> of one TestCase, which unittest runs
        # sorted by name: not in the file's order
        for test in sorted(plan.tests, key=lambda t: t.test_name or t.name or t.type):
            run = _run_test(test, plan, package, uri, log_dir, env, opts.text)
            runs.append(run)
            verdict = {"ok": "ok", "failure": "FAILURE!", "error": "ERROR!"}[run.verdict]
            print(f"[Testcase: test{run.name}] ... {verdict}", flush=True)
            if run.why:
                print(f"{verdict.rstrip('!')}: {run.why}", flush=True)
    finally:
        if nodes is not None:
            _stop(nodes)
        if core is not None:
            _stop(core)
    cases = [case for run in runs for case in run.cases]
    # as ROS 1 writes it, the combined file holds rostest's own case per <test> (``test<name>``, passing
    # when the node ran and wrote its results; failing when it could not run or wrote none; an error
    # when it overran); the node's own cases are in its rosunit-<name>.xml beside it, so
    # catkin_test_results counts each case once
    own = [
        CaseResult(
            "rostest.runner.RosTest",
            f"test{run.name}",
            failure=run.why if run.verdict == "failure" else None,
            error=run.why if run.verdict == "error" else None,
        )
        for run in runs
    ]
    write_xml(Path(combined), SuiteResult(name=suite_name, cases=own))
    log_file.parent.mkdir(parents=True, exist_ok=True)
    report = _report(package, runs, log_file)
    log_file.write_text(report + "\n", encoding="utf-8")
    if opts.text:
        print("WARNING: overall test result is not accurate when --text is enabled")
        print(f"rostest log file is in {log_file}")
    else:
        print(report, flush=True)
    if any(run.verdict != "ok" for run in runs):
        return 1
    return 2 if any(not case.passed for case in cases) else 0


console_main = entry(main)

"""Run a Python ``unittest`` suite as ROS 1's ``rostest.rosrun`` / ``rosunit.unitrun`` do.

A test node is an ordinary script ending in ``rostest.rosrun(PKG, 'name', TestCase)``: it runs the
cases, prints ``[Testcase: ...]`` lines and rosunit's SUMMARY, writes JUnit XML to the file rostest
passed as ``--gtest_output=xml:<file>`` (or ``~/.ros/test_results/<pkg>/rosunit-<name>.xml``), and
exits 1 when a case failed, which is how rostest learns the outcome.
"""

from __future__ import annotations

import io
import sys
import time
import traceback
import unittest
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from ninjemys.rostest.junit import XML_OUTPUT_FLAG, CaseResult, SuiteResult, results_file, write_xml

#: unittest aliases Python 3.12 removed and Noetic-era tests (Python 3.8) still call
_REMOVED_ALIASES = {
    "assertEquals": "assertEqual",
    "assertNotEquals": "assertNotEqual",
    "assert_": "assertTrue",
    "assertAlmostEquals": "assertAlmostEqual",
    "assertNotAlmostEquals": "assertNotAlmostEqual",
    "failUnless": "assertTrue",
    "failIf": "assertFalse",
    "failUnlessEqual": "assertEqual",
    "failIfEqual": "assertNotEqual",
    "failUnlessAlmostEqual": "assertAlmostEqual",
    "failIfAlmostEqual": "assertNotAlmostEqual",
    "failUnlessRaises": "assertRaises",
    "assertRegexpMatches": "assertRegex",
    "assertNotRegexpMatches": "assertNotRegex",
    "assertRaisesRegexp": "assertRaisesRegex",
}


def restore_removed_aliases() -> None:
    """Give ``unittest.TestCase`` back the old names where this Python lacks them (3.12+)."""
    for old, new in _REMOVED_ALIASES.items():
        if not hasattr(unittest.TestCase, old):
            setattr(unittest.TestCase, old, getattr(unittest.TestCase, new))


class _Recorder(unittest.TextTestResult):
    """TextTestResult that also keeps each case's outcome and duration for the XML file."""

    def __init__(self, stream: Any, descriptions: bool, verbosity: int) -> None:
        super().__init__(stream, descriptions, verbosity)
        self.cases: list[CaseResult] = []
        self._started = 0.0

    def startTest(self, test: unittest.TestCase) -> None:  # noqa: N802 - unittest's name
        self._started = time.monotonic()
        super().startTest(test)

    def _case(self, test: unittest.TestCase) -> CaseResult:
        case_id = test.id()
        classname, _, name = case_id.rpartition(".")
        case = CaseResult(
            classname=classname or case_id, name=name or case_id, time=time.monotonic() - self._started
        )
        self.cases.append(case)
        return case

    def addSuccess(self, test: unittest.TestCase) -> None:  # noqa: N802
        super().addSuccess(test)
        self._case(test)

    def addFailure(self, test: unittest.TestCase, err: Any) -> None:  # noqa: N802
        super().addFailure(test, err)
        self._case(test).failure = _junit_text(err)

    def addError(self, test: unittest.TestCase, err: Any) -> None:  # noqa: N802
        super().addError(test, err)
        self._case(test).error = _junit_text(err)

    def addSkip(self, test: unittest.TestCase, reason: str) -> None:  # noqa: N802
        super().addSkip(test, reason)
        self._case(test)


def _junit_text(err: Any) -> str:
    """rosunit's text for a failed case: the exception's message, then the stack."""
    _kind, value, tb = err
    return f"{value}\n" + "".join(traceback.format_tb(tb)).rstrip()


def load_suite(test: Any) -> unittest.TestSuite:
    """A suite from a TestCase class, a TestCase/TestSuite instance or a dotted name, as rostest takes."""
    loader = unittest.TestLoader()
    if isinstance(test, str):
        return loader.loadTestsFromName(test)
    if isinstance(test, type) and issubclass(test, unittest.TestCase):
        return loader.loadTestsFromTestCase(test)
    if isinstance(test, unittest.TestSuite):
        return test
    if isinstance(test, unittest.TestCase):
        return unittest.TestSuite([test])
    raise TypeError(f"rostest: cannot run {test!r}: give a unittest.TestCase class, a suite or a dotted name")


def parse_args(sysargs: Sequence[str]) -> tuple[Path | None, bool]:
    """(results file from ``--gtest_output=xml:``, whether ``--text`` was given)."""
    result = None
    for arg in sysargs:
        if arg.startswith(XML_OUTPUT_FLAG):
            result = Path(arg[len(XML_OUTPUT_FLAG) :])
    return result, "--text" in sysargs


def summary(cases: list[CaseResult], tests_run: int) -> str:
    """rosunit's SUMMARY block (the RESULT line green on success, as ROS 1 prints it)."""
    failed = [c for c in cases if c.failure is not None]
    errored = [c for c in cases if c.error is not None]
    ok = not failed and not errored
    lines = ["-------------------------------------------------------------", "SUMMARY:"]
    lines.append("\033[32m * RESULT: SUCCESS\033[0m" if ok else " * RESULT: FAIL")
    lines.append(f" * TESTS: {tests_run}")
    lines.append(f" * ERRORS: {len(errored)} [{', '.join(c.name for c in errored)}]")
    lines.append(f" * FAILURES: {len(failed)} [{', '.join(c.name for c in failed)}]")
    return "\n".join(lines) + "\n"


def run_suite(
    suite: unittest.TestSuite, test_name: str, results: Path, text_mode: bool = False
) -> unittest.TestResult:
    """Run ``suite``: console lines (rosunit's, or unittest's own with ``text_mode``), the XML file
    at ``results``; the unittest result is returned (``wasSuccessful()``, ``failures`` ...)."""
    restore_removed_aliases()
    buffer = io.StringIO()
    stream: Any = sys.stderr if text_mode else buffer
    started = time.monotonic()
    outcome = unittest.TextTestRunner(stream=stream, verbosity=2, resultclass=_Recorder).run(suite)
    assert isinstance(outcome, _Recorder)
    if not text_mode:
        print(f"[ROSUNIT] Outputting test results to {results}")
        for case in outcome.cases:
            verdict = "ok" if case.passed else ("FAILURE!" if case.failure is not None else "ERROR!")
            print(f"[Testcase: {case.name}] ... {verdict}")
            for label, text in (("FAILURE", case.failure), ("ERROR", case.error)):
                if text:
                    print(f"{label}: {text.strip().splitlines()[-1]}")
                    print(text, end="" if text.endswith("\n") else "\n")
                    print("-" * 80)
    elapsed = time.monotonic() - started
    write_xml(
        results, SuiteResult(name=test_name, cases=outcome.cases, time=elapsed, system_out=buffer.getvalue())
    )
    sys.stdout.flush()
    return outcome


def run(
    package: str, test_name: str, test: Any, sysargs: Sequence[str] | None = None, is_rostest: bool = False
) -> bool:
    """``rostest.rosrun``'s work without its exit: run, write the XML, print the SUMMARY; True when
    every case passed."""
    results, text_mode = parse_args(sys.argv if sysargs is None else sysargs)
    if results is None:
        results = results_file(package, Path(test_name).name, is_rostest)
    outcome = run_suite(load_suite(test), test_name, results, text_mode)
    cases = outcome.cases if isinstance(outcome, _Recorder) else []
    print(summary(cases, outcome.testsRun))
    sys.stdout.flush()
    return outcome.wasSuccessful()


__all__ = ["load_suite", "parse_args", "restore_removed_aliases", "run", "run_suite", "summary"]

"""rosunit, ROS 1's unit-test runner, as provided by ninjemys (``import rosunit``).

Offline tests (no ROS graph) call ``rosunit.unitrun(PKG, 'name', TestCase)``; results go to
``~/.ros/test_results/<pkg>/rosunit-<name>.xml`` as JUnit XML. The work is done by
:mod:`ninjemys.rostest.pyunit`; names and arguments follow rosunit 1.15.
"""

from __future__ import annotations

import os
import sys
import unittest
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from ninjemys.rostest.junit import XML_OUTPUT_FLAG, results_file
from ninjemys.rostest.pyunit import load_suite, parse_args, run_suite, summary

__all__ = [
    "XML_OUTPUT_FLAG",
    "create_xml_runner",
    "print_unittest_summary",
    "rostest_name_from_path",
    "unitrun",
    "xml_results_file",
]


def xml_results_file(test_pkg: str, test_name: str, is_rostest: bool = False, env: Any = None) -> str:
    """Where a test's JUnit XML goes (its directory is created, as rosunit does)."""
    path = results_file(test_pkg, test_name, is_rostest, env)
    path.parent.mkdir(parents=True, exist_ok=True)
    return str(path)


def rostest_name_from_path(pkg_dir: str, test_file: str) -> str:
    """A .test file's name for its results: the package-relative path, ``/`` as ``_``, no extension."""
    test_file = os.path.abspath(test_file)
    if test_file.startswith(pkg_dir):
        test_file = test_file[len(pkg_dir) :].lstrip(os.sep)
    name = test_file.replace(os.sep, "_")
    return name[: name.rfind(".")] if "." in name else name


class _XMLRunner:
    """What create_xml_runner returns: ``run(suite)`` writes the XML and returns unittest's result."""

    def __init__(self, test_name: str, results: str) -> None:
        self.test_name = test_name
        self.results = results

    def run(self, suite: unittest.TestSuite) -> unittest.TestResult:
        return run_suite(suite, self.test_name, Path(self.results))


def create_xml_runner(
    test_pkg: str, test_name: str, results_file: str | None = None, is_rostest: bool = False
) -> _XMLRunner:
    """A runner whose results go to ``results_file`` (default: :func:`xml_results_file`)."""
    test_name = os.path.basename(test_name)
    return _XMLRunner(test_name, results_file or xml_results_file(test_pkg, test_name, is_rostest))


def print_unittest_summary(result: unittest.TestResult) -> None:
    """rosunit's SUMMARY block for a unittest result."""
    cases = getattr(result, "cases", [])
    print(summary(cases, result.testsRun))


def unitrun(
    package: str,
    test_name: str,
    test: Any,
    sysargs: Sequence[str] | None = None,
    coverage_packages: Sequence[str] | None = None,
) -> None:
    """Run an offline test suite with XML results; exits 1 when a case failed (coverage is not
    collected: ``coverage_packages`` is accepted and ignored)."""
    del coverage_packages
    results, text_mode = parse_args(sys.argv if sysargs is None else sysargs)
    target = results or xml_results_file(package, test_name)
    outcome = run_suite(load_suite(test), test_name, Path(target), text_mode)
    print_unittest_summary(outcome)
    if not outcome.wasSuccessful():
        sys.exit(1)

"""JUnit XML test results, where and how ROS 1 writes them (``~/.ros/test_results/<pkg>/``).

rostest gathers what each test node wrote into one file per ``.test`` file; CI tools (and
``catkin_test_results``) read these. Files written by gtest (``<testsuites>``) and by Python's
runners (``<testsuite>``) are both read.
"""

from __future__ import annotations

import os
import xml.etree.ElementTree as ET
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path

from ninjemys.errors import NinjemysError

#: the argument rostest gives each test node: ``--gtest_output=xml:<results file>``
XML_OUTPUT_FLAG = "--gtest_output=xml:"


class TestResultsError(NinjemysError):
    """A results file that cannot be read or written (names the file)."""


@dataclass
class CaseResult:
    """One test case; ``failure``/``error`` hold the message and traceback when it did not pass."""

    classname: str
    name: str
    time: float = 0.0
    failure: str | None = None
    error: str | None = None

    @property
    def passed(self) -> bool:
        return self.failure is None and self.error is None


@dataclass
class SuiteResult:
    """A test suite (a test node's results, or a whole .test file's)."""

    name: str
    cases: list[CaseResult] = field(default_factory=list)
    time: float = 0.0
    system_out: str = ""

    @property
    def failures(self) -> list[CaseResult]:
        return [c for c in self.cases if c.failure is not None]

    @property
    def errors(self) -> list[CaseResult]:
        return [c for c in self.cases if c.error is not None]

    @property
    def ok(self) -> bool:
        return all(c.passed for c in self.cases)


def test_results_dir(env: Mapping[str, str] | None = None) -> Path:
    """``ROS_TEST_RESULTS_DIR``, else ``$ROS_HOME/test_results`` (``~/.ros/test_results``)."""
    env = os.environ if env is None else env
    if env.get("ROS_TEST_RESULTS_DIR"):
        return Path(env["ROS_TEST_RESULTS_DIR"])
    home = env.get("ROS_HOME") or os.path.join(os.path.expanduser("~"), ".ros")
    return Path(home) / "test_results"


def results_file(
    package: str, test_name: str, is_rostest: bool = False, env: Mapping[str, str] | None = None
) -> Path:
    """``<results dir>/<pkg>/rosunit-<name>.xml`` (``rostest-`` for a whole .test file), with the
    characters ROS 1 replaces in the name (spaces, quotes, slashes ...) turned into ``_``."""
    for char in " \"'&$!`/\\":
        test_name = test_name.replace(char, "_")
    prefix = "rostest" if is_rostest else "rosunit"
    return test_results_dir(env) / package / f"{prefix}-{test_name}.xml"


def write_xml(path: Path, suite: SuiteResult) -> None:
    """Write one ``<testsuite>`` file (directories made as needed)."""
    root = ET.Element(
        "testsuite",
        name=suite.name,
        tests=str(len(suite.cases)),
        errors=str(len(suite.errors)),
        failures=str(len(suite.failures)),
        time=f"{suite.time:.3f}",
    )
    for case in suite.cases:
        el = ET.SubElement(
            root, "testcase", classname=case.classname, name=case.name, time=f"{case.time:.3f}"
        )
        for tag, text in (("failure", case.failure), ("error", case.error)):
            if text is not None:
                child = ET.SubElement(
                    el,
                    tag,
                    type=tag.capitalize(),
                    message=text.strip().splitlines()[-1] if text.strip() else "",
                )
                child.text = text
    ET.SubElement(root, "system-out").text = suite.system_out
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        ET.ElementTree(root).write(path, encoding="utf-8", xml_declaration=True)
    except OSError as exc:
        raise TestResultsError(f"cannot write test results [{path}]: {exc.strerror}") from None


def read_xml(path: Path) -> SuiteResult:
    """The cases of a results file (``<testsuite>`` or gtest's ``<testsuites>``)."""
    try:
        root = ET.parse(path).getroot()
    except OSError as exc:
        raise TestResultsError(f"cannot read test results [{path}]: {exc.strerror}") from None
    except ET.ParseError as exc:
        raise TestResultsError(f"{path}: malformed test results: {exc}") from None
    suites = [root] if root.tag == "testsuite" else list(root.iter("testsuite"))
    result = SuiteResult(name=root.get("name", path.stem))
    for suite in suites:
        for case in suite.iter("testcase"):
            failure = case.find("failure")
            error = case.find("error")
            result.cases.append(
                CaseResult(
                    classname=case.get("classname", suite.get("name", "")),
                    name=case.get("name", ""),
                    time=float(case.get("time") or 0.0),
                    failure=None if failure is None else (failure.text or failure.get("message") or "failed"),
                    error=None if error is None else (error.text or error.get("message") or "error"),
                )
            )
        result.time += float(suite.get("time") or 0.0)
    return result


__all__ = [
    "XML_OUTPUT_FLAG",
    "CaseResult",
    "SuiteResult",
    "TestResultsError",
    "read_xml",
    "results_file",
    "test_results_dir",
    "write_xml",
]

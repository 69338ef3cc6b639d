"""``catkin_test_results [DIR] [--all] [--verbose]``: the summary of a workspace's JUnit results.

The step after ``catkin_make run_tests`` in every catkin CI (GitHub workflows, course templates):
``catkin_make run_tests`` never fails on a failing test, this command does. Same walk, counts,
output and exit status as catkin's: every ``*.xml`` under DIR (default: the current directory; not
into dot-directories) read as a ``<testsuite>`` or ``<testsuites>`` file, one line per file with
errors, failures or skipped tests (``--all``: every file, and the files that are not JUnit), then
``Summary: N tests, E errors, F failures, S skipped``; exit 1 if anything erred or failed.
"""

from __future__ import annotations

import argparse
import os
import sys
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from pathlib import Path

from ninjemys.tools.cli import entry


@dataclass(frozen=True)
class Counts:
    tests: int = 0
    errors: int = 0
    failures: int = 0
    skipped: int = 0

    def __add__(self, other: Counts) -> Counts:
        return Counts(
            self.tests + other.tests,
            self.errors + other.errors,
            self.failures + other.failures,
            self.skipped + other.skipped,
        )


def _suite_counts(el: ET.Element) -> Counts:
    """One element's attributes; KeyError when tests/errors/failures is missing."""
    skipped = sum(int(el.get(k, "0")) for k in ("skip", "skipped", "disabled"))
    return Counts(int(el.attrib["tests"]), int(el.attrib["errors"]), int(el.attrib["failures"]), skipped)


def read_counts(path: Path) -> Counts:
    """The counts of one JUnit file. A ``<testsuites>`` root adds its own attributes to its
    children's, as catkin does (gtest files, which carry both, count twice there too)."""
    root = ET.parse(path).getroot()
    if root.tag == "testsuite":
        return _suite_counts(root)
    if root.tag != "testsuites":
        raise ValueError("the root tag is neither 'testsuite' nor 'testsuites'")
    total = Counts()
    for el in (root, *(child for child in root if child.tag == "testsuite")):
        try:
            total += _suite_counts(el)
        except KeyError:
            pass
    return total


def collect(base: Path, show_all: bool = False, verbose: bool = False) -> dict[str, Counts]:
    """Every readable JUnit file under ``base``, by path relative to it."""
    results: dict[str, Counts] = {}
    for dirpath, dirnames, filenames in os.walk(base):
        dirnames[:] = [d for d in dirnames if not d.startswith(".")]
        for filename in filenames:
            if not filename.endswith(".xml"):
                continue
            path = Path(dirpath) / filename
            name = str(path)[len(str(base)) + 1 :]
            try:
                counts = read_counts(path)
            except (ET.ParseError, ValueError, KeyError, OSError) as exc:
                if show_all:
                    print(f'Skipping "{name}": {exc}')
                continue
            results[name] = counts
            if verbose and counts.errors + counts.failures > 0:
                print(f"Full test results for '{name}'")
                print("-------------------------------------------------")
                print(path.read_text(encoding="utf-8", errors="replace"))
                print("-------------------------------------------------")
    return results


def summary(results: dict[str, Counts], show_all: bool = False) -> tuple[str, Counts]:
    lines = []
    total = Counts()
    for name in sorted(results):
        c = results[name]
        total += c
        if show_all and not (c.errors or c.failures or c.skipped):
            lines.append(f"{name}: {c.tests} tests")
        if c.errors or c.failures or c.skipped:
            lines.append(
                f"{name}: {c.tests} tests, {c.errors} errors, {c.failures} failures, {c.skipped} skipped"
            )
    lines.append(
        f"Summary: {total.tests} tests, {total.errors} errors, {total.failures} failures, {total.skipped} skipped"
    )
    return "\n".join(lines), total


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(
        prog="catkin_test_results",
        description="Outputs a summary of the test results. If there are any test errors or failures "
        "the scripts return code is 1.",
    )
    p.add_argument("test_results_dir", nargs="?", default=os.curdir, help="The path to the test results")
    p.add_argument(
        "--all",
        action="store_true",
        help="Show all test results even the ones without errors/failures as well as skipped xml files",
    )
    p.add_argument("--verbose", action="store_true", help="Show all tests which have errors or failed")
    args = p.parse_args(argv)
    base = Path(os.path.abspath(args.test_results_dir))
    if not base.is_dir():
        print(f'Test results directory "{base}" does not exist', file=sys.stderr)
        return 1
    text, total = summary(collect(base, show_all=args.all, verbose=args.verbose), show_all=args.all)
    print(text)
    sys.stdout.flush()
    return 1 if total.errors or total.failures else 0


console_main = entry(main)

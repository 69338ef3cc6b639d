"""``catkin_test_results``: the CI step after ``catkin_make run_tests`` (test_packages_tutorial's
workflow), shipped so a pip-only install has it; same output and exit status as Debian's."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

OURS = str(Path(sys.executable).parent / "catkin_test_results")
DEBIAN = "/usr/bin/catkin_test_results"

PASSING = '<testsuite name="a" tests="2" errors="0" failures="0"><testcase name="x"/></testsuite>'
FAILING = (
    '<testsuite name="b" tests="3" errors="1" failures="1" skipped="1">'
    '<testcase name="y"><failure message="no">1 != 2</failure></testcase></testsuite>'
)
#: gtest's layout: the root carries totals too (catkin adds them to the children's)
GTEST = (
    '<testsuites tests="2" failures="1" disabled="0" errors="0" name="AllTests">'
    '<testsuite name="Math" tests="2" failures="1" disabled="1" errors="0"/></testsuites>'
)


def _results(root: Path) -> Path:
    base = root / "test_results"
    (base / "pkg_a").mkdir(parents=True)
    (base / "pkg_b").mkdir()
    (base / ".hidden").mkdir()
    (base / "pkg_a" / "rostest-test_ok.xml").write_text(PASSING)
    (base / "pkg_a" / "rosunit-fails.xml").write_text(FAILING)
    (base / "pkg_b" / "gtest-math.xml").write_text(GTEST)
    (base / "pkg_b" / "package.xml").write_text("<package><name>pkg_b</name></package>")
    (base / "pkg_b" / "broken.xml").write_text("<testsuite")
    (base / ".hidden" / "rostest-ignored.xml").write_text(FAILING)
    (base / "pkg_b" / "notes.txt").write_text("not xml")
    return base


def _run(command: str, *args: str, cwd: Path) -> tuple[int, str, str]:
    done = subprocess.run(
        [command, *args],
        cwd=cwd,
        env={"PATH": "/usr/bin:/bin", "LANG": "C.UTF-8"},
        capture_output=True,
        text=True,
        timeout=60,
        check=False,
    )
    return done.returncode, done.stdout, done.stderr


def test_summary_lines_and_exit_status(tmp_path: Path) -> None:
    base = _results(tmp_path)
    code, out, _err = _run(OURS, str(base), cwd=tmp_path)
    assert code == 1
    assert out.splitlines() == [
        "pkg_a/rosunit-fails.xml: 3 tests, 1 errors, 1 failures, 1 skipped",
        "pkg_b/gtest-math.xml: 4 tests, 0 errors, 2 failures, 1 skipped",
        "Summary: 9 tests, 1 errors, 3 failures, 2 skipped",
    ]
    (base / "pkg_a" / "rosunit-fails.xml").unlink()
    (base / "pkg_b" / "gtest-math.xml").unlink()
    code, out, _err = _run(OURS, "--all", cwd=base)
    assert code == 0
    assert "pkg_a/rostest-test_ok.xml: 2 tests" in out.splitlines()
    assert 'Skipping "pkg_b/package.xml": the root tag is neither' in out
    assert out.splitlines()[-1] == "Summary: 2 tests, 0 errors, 0 failures, 0 skipped"


def test_a_missing_directory_is_one_line(tmp_path: Path) -> None:
    code, out, err = _run(OURS, "nowhere", cwd=tmp_path)
    assert (code, out) == (1, "")
    assert err == f'Test results directory "{tmp_path / "nowhere"}" does not exist\n'


@pytest.mark.ros1
@pytest.mark.skipif(not Path(DEBIAN).exists(), reason="Debian's catkin_test_results is not installed")
@pytest.mark.parametrize("args", [(), ("--all",), ("--verbose",), ("--all", "--verbose")])
def test_same_output_as_debians(tmp_path: Path, args: tuple[str, ...]) -> None:
    base = _results(tmp_path)
    ours = _run(OURS, *args, cwd=base)
    theirs = _run(DEBIAN, *args, cwd=base)
    assert ours[0] == theirs[0] == 1
    assert ours[1] == theirs[1]
    assert _run(OURS, "gone", cwd=base)[::2] == _run(DEBIAN, "gone", cwd=base)[::2]

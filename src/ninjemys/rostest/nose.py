"""``catkin_add_nosetests(path)`` tests, collected and run as nose 1.3 does, results in nose's xunit.

catkin 0.8 runs ``nosetests -P --where=<dir> --with-xunit --xunit-file=...`` for each
``catkin_add_nosetests`` of a package. nose is unmaintained (it does not import on Python 3.12),
so ninjemys collects by nose's rules itself and writes the same ``<testsuite name="nosetests">``
file, which ``catkin_test_results`` and CI read:

- a directory is searched for ``.py`` files whose name matches nose's ``testMatch``, recursing into
  Python packages, ``lib``/``src`` and directories whose name matches; executable files are skipped (nose's
  default without ``--exe``); a file given directly is always loaded;
- in a module: ``unittest.TestCase`` subclasses (any name), then other classes whose name matches
  (sorted by name), then functions whose name matches (in source order); methods whose name matches;
- fixtures: ``setup_module``/``teardown_module`` (and nose's other spellings), ``setup_class``,
  ``setup``/``setUp`` of plain classes, ``with_setup`` attributes left by nose's decorator;
- ``-P``: the test directory is not put on ``sys.path`` (a sibling import fails, as under catkin);
- catkin's ``--process-timeout`` is nose's multiprocess plugin's, which catkin leaves off: no timeout.

Run as ``python -m ninjemys.rostest.nose PATH --xunit-file FILE``; the exit code is 0 only when all
tests passed (catkin's run_tests target ignores it, as ROS 1 does).
"""

from __future__ import annotations

import argparse
import functools
import importlib.util
import inspect
import os
import re
import sys
import time
import traceback
import types
import unittest
import xml.etree.ElementTree as ET
from collections.abc import Callable, Iterator
from pathlib import Path

from ninjemys.errors import NinjemysError

#: nose's default testMatch
TEST_MATCH = re.compile(r"(?:^|[\b_\./-])[Tt]est")


class NoseError(NinjemysError):
    """A nosetests path that does not exist (catkin: "Can't find nosetests path")."""


def wanted(name: str) -> bool:
    return TEST_MATCH.search(name) is not None


def module_files(path: Path) -> Iterator[Path]:
    """The test modules under ``path`` in nose's order (names sorted, files before directories)."""
    if path.is_file():
        yield path
        return
    entries = sorted(path.iterdir(), key=lambda p: p.name)
    for entry in entries:
        if (
            entry.is_file()
            and entry.suffix == ".py"
            and wanted(entry.stem)
            and not entry.name.startswith(".")
        ):
            if os.access(entry, os.X_OK):
                continue  # nose without --exe ignores executable files
            yield entry
    for entry in entries:
        if entry.is_dir() and not entry.name.startswith((".", "_")):
            if (entry / "__init__.py").is_file() or wanted(entry.name) or entry.name in ("lib", "src"):
                yield from module_files(entry)


def dotted_name(path: Path) -> str:
    """The module's name as nose gives it: the file's stem below the enclosing packages."""
    parts = [] if path.name == "__init__.py" else [path.stem]
    parent = path.parent
    while (parent / "__init__.py").is_file():
        parts.insert(0, parent.name)
        parent = parent.parent
    return ".".join(parts)


def import_file(path: Path) -> types.ModuleType:
    """Import ``path`` under its dotted name (its packages first), without touching ``sys.path``."""
    name = dotted_name(path)
    chain = name.split(".")
    module: types.ModuleType | None = None
    for depth in range(1, len(chain) + 1):
        qualified = ".".join(chain[:depth])
        if qualified in sys.modules:
            module = sys.modules[qualified]
            continue
        if depth < len(chain):
            pkg_dir = path.parent.joinpath(*([".."] * (len(chain) - depth - 1))).resolve()
            spec = importlib.util.spec_from_file_location(
                qualified, pkg_dir / "__init__.py", submodule_search_locations=[str(pkg_dir)]
            )
        else:
            spec = importlib.util.spec_from_file_location(qualified, path)
        assert spec is not None and spec.loader is not None
        module = importlib.util.module_from_spec(spec)
        sys.modules[qualified] = module
        spec.loader.exec_module(module)
    assert module is not None
    return module


def _fixture(obj: object, *names: str) -> Callable[[], object] | None:
    for name in names:
        fn = getattr(obj, name, None)
        if callable(fn):
            return fn
    return None


class _FunctionCase(unittest.FunctionTestCase):
    """A test function or plain-class method, named as nose names it in the xunit file."""

    def __init__(
        self,
        fn: Callable[[], object],
        classname: str,
        name: str,
        setup: Callable[[], object] | None = None,
        teardown: Callable[[], object] | None = None,
    ) -> None:
        super().__init__(fn, setUp=setup, tearDown=teardown)
        self.nose_id = (classname, name)

    def id(self) -> str:
        return ".".join(self.nose_id)

    def __str__(self) -> str:
        return self.id()


class _ModuleSuite(unittest.TestSuite):
    """A module's tests between its ``setup_module`` and ``teardown_module``."""

    def __init__(self, module: types.ModuleType, tests: list[unittest.TestCase]) -> None:
        super().__init__(tests)
        self.module = module

    def run(self, result: unittest.TestResult, debug: bool = False) -> unittest.TestResult:
        setup = _fixture(self.module, "setup_module", "setupModule", "setUpModule", "setup", "setUp")
        teardown = _fixture(
            self.module, "teardown_module", "teardownModule", "tearDownModule", "teardown", "tearDown"
        )
        try:
            if setup is not None:
                setup()
        except Exception:
            result.addError(_FunctionCase(lambda: None, self.module.__name__, "setup"), sys.exc_info())
            return result
        try:
            return super().run(result, debug)
        finally:
            if teardown is not None:
                teardown()


def _plain_class_tests(cls: type, module_name: str) -> list[unittest.TestCase]:
    tests: list[unittest.TestCase] = []
    classname = f"{module_name}.{cls.__name__}"
    names = sorted(n for n in dir(cls) if wanted(n) and callable(getattr(cls, n)))
    for name in names:
        instance = cls()
        method = getattr(instance, name)
        tests.append(
            _FunctionCase(
                method,
                classname,
                name,
                _fixture(instance, "setup", "setUp"),
                _fixture(instance, "teardown", "tearDown"),
            )
        )
    return tests


def _function_tests(fn: Callable[..., object], module_name: str) -> list[unittest.TestCase]:
    setup, teardown = getattr(fn, "setup", None), getattr(fn, "teardown", None)
    if not inspect.isgeneratorfunction(fn):
        return [_FunctionCase(fn, module_name, fn.__name__, setup, teardown)]
    tests: list[unittest.TestCase] = []
    for item in fn():  # nose's test generators: each (callable, *args) is a test
        call, *args = item if isinstance(item, tuple) else (item,)
        tests.append(
            _FunctionCase(
                functools.partial(call, *args),
                module_name,
                f"{fn.__name__}{tuple(args)!r}",
                setup,
                teardown,
            )
        )
    return tests


def module_tests(module: types.ModuleType) -> unittest.TestSuite:
    """The tests nose finds in ``module``, in nose's order: classes by name, then functions by line."""
    loader = unittest.TestLoader()
    loader.testMethodPrefix = ""  # names are chosen by testMatch below
    name = module.__name__
    # as nose: every name the module holds (imported ones too), none starting with "_", and
    # ``__test__ = False`` opts out
    items = [v for k, v in vars(module).items() if not k.startswith("_") and getattr(v, "__test__", True)]
    classes = sorted(
        (c for c in items if inspect.isclass(c) and not c.__name__.startswith("_")),
        key=lambda c: c.__name__,
    )
    tests: list[unittest.TestCase] = []
    for cls in classes:
        if issubclass(cls, unittest.TestCase):
            method_names = sorted(n for n in dir(cls) if wanted(n) and callable(getattr(cls, n)))
            tests.extend(cls(n) for n in method_names)
        elif wanted(cls.__name__):
            tests.extend(_class_suite(cls, name))
    functions = sorted(
        (f for f in items if inspect.isfunction(f) and not f.__name__.startswith("_") and wanted(f.__name__)),
        key=lambda f: f.__code__.co_firstlineno,
    )
    for fn in functions:
        tests.extend(_function_tests(fn, name))
    return _ModuleSuite(module, tests)


def _class_suite(cls: type, module_name: str) -> list[unittest.TestCase]:
    """A plain test class's methods; ``setup_class``/``teardown_class`` around them."""
    tests = _plain_class_tests(cls, module_name)
    setup = _fixture(cls, "setup_class", "setupClass", "setUpClass", "setupAll", "setUpAll")
    teardown = _fixture(cls, "teardown_class", "teardownClass", "tearDownClass", "teardownAll")
    if tests and setup is not None:
        first = tests[0]
        inner_setup = first._setUpFunc  # type: ignore[attr-defined]
        first._setUpFunc = lambda: (setup(), inner_setup and inner_setup())  # type: ignore[attr-defined]
    if tests and teardown is not None:
        last = tests[-1]
        inner_teardown = last._tearDownFunc  # type: ignore[attr-defined]
        last._tearDownFunc = lambda: (inner_teardown and inner_teardown(), teardown())  # type: ignore[attr-defined]
    return tests


class XunitResult(unittest.TextTestResult):
    """unittest's console result, also keeping each case's outcome for the xunit file."""

    def __init__(self, *args: object, **kwargs: object) -> None:
        super().__init__(*args, **kwargs)  # type: ignore[arg-type]
        self.records: list[tuple[unittest.TestCase, str, str, str, float]] = []
        self._started = 0.0

    def startTest(self, test: unittest.TestCase) -> None:
        self._started = time.monotonic()
        super().startTest(test)

    def _record(self, test: unittest.TestCase, kind: str, err: object = None, message: str = "") -> None:
        text = ""
        if isinstance(err, tuple):
            exc_type, exc, tb = err
            text = "".join(traceback.format_exception(exc_type, exc, tb))
            message = str(exc)
            kind = f"{kind}:{exc_type.__module__}.{exc_type.__qualname__}"
        self.records.append((test, kind, message, text, time.monotonic() - self._started))

    def addSuccess(self, test: unittest.TestCase) -> None:
        super().addSuccess(test)
        self._record(test, "ok")

    def addFailure(self, test: unittest.TestCase, err: object) -> None:
        super().addFailure(test, err)  # type: ignore[arg-type]
        self._record(test, "failure", err)

    def addError(self, test: unittest.TestCase, err: object) -> None:
        super().addError(test, err)  # type: ignore[arg-type]
        self._record(test, "error", err)

    def addSkip(self, test: unittest.TestCase, reason: str) -> None:
        super().addSkip(test, reason)
        self._record(test, "skipped:unittest.case.SkipTest", message=reason)


def _case_id(test: unittest.TestCase) -> tuple[str, str]:
    if isinstance(test, _FunctionCase):
        return test.nose_id
    return f"{type(test).__module__}.{type(test).__qualname__}", test._testMethodName


def write_xunit(path: Path, result: XunitResult) -> None:
    """nose's xunit file: one ``<testsuite name="nosetests">`` with tests/errors/failures/skip."""
    counts = {"error": 0, "failure": 0, "skipped": 0}
    root = ET.Element("testsuite", name="nosetests")
    for test, kind, message, text, seconds in result.records:
        classname, name = _case_id(test)
        case = ET.SubElement(root, "testcase", classname=classname, name=name, time=f"{seconds:.3f}")
        outcome, _, exc_type = kind.partition(":")
        if outcome in counts:
            counts[outcome] += 1
            child = ET.SubElement(case, outcome, type=exc_type, message=message)
            child.text = text or None
    root.set("tests", str(len(result.records)))
    root.set("errors", str(counts["error"]))
    root.set("failures", str(counts["failure"]))
    root.set("skip", str(counts["skipped"]))
    path.parent.mkdir(parents=True, exist_ok=True)
    ET.ElementTree(root).write(path, encoding="UTF-8", xml_declaration=True)


def run(path: Path, xunit_file: Path) -> bool:
    """Collect and run the tests at ``path``; write ``xunit_file``; True when all passed."""
    if not path.exists():
        raise NoseError(f"Can't find nosetests path '{path}'")
    suite = unittest.TestSuite()
    runner = unittest.TextTestRunner(stream=sys.stderr, resultclass=XunitResult)
    for file in module_files(path):
        try:
            suite.addTest(module_tests(import_file(file)))
        except Exception:
            failed = _FunctionCase(lambda: None, "nose.failure.Failure", "runTest")  # nose's id
            error = sys.exc_info()
            suite.addTest(_ImportFailure(failed, error))
    result = runner.run(suite)
    assert isinstance(result, XunitResult)
    write_xunit(xunit_file, result)
    return result.wasSuccessful()


class _ImportFailure(unittest.TestSuite):
    """A module that does not import: one error case, as nose's ``Failure`` test."""

    def __init__(self, case: _FunctionCase, error: object) -> None:
        super().__init__()
        self.case, self.error = case, error

    def run(self, result: unittest.TestResult, debug: bool = False) -> unittest.TestResult:
        result.startTest(self.case)
        result.addError(self.case, self.error)  # type: ignore[arg-type]
        result.stopTest(self.case)
        return result


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m ninjemys.rostest.nose")
    parser.add_argument("path", type=Path, help="a test directory or file")
    parser.add_argument("--xunit-file", type=Path, required=True)
    args = parser.parse_args(argv)
    try:
        return 0 if run(args.path, args.xunit_file) else 1
    except NoseError as exc:
        print(exc, file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())

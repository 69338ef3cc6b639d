"""Tree-wide rules of the house: one exception tree, and a docstring face on every package.

- Every exception class defined in ``src/ninjemys`` derives from :class:`ninjemys.errors.NinjemysError`,
  so ``except NinjemysError`` catches everything ninjemys raises on purpose (classes that must stay
  outside are listed in ``OUTSIDE`` with the reason).
- Every package (a folder with ``__init__.py``) says in its docstring what it is for.
"""

from __future__ import annotations

import ast
import importlib
import inspect
import pkgutil
from pathlib import Path

import ninjemys
from ninjemys.errors import NinjemysError

PACKAGE_ROOT = Path(ninjemys.__file__).resolve().parent

#: exception classes that stay outside the tree on purpose: module.Class -> why
OUTSIDE = {
    # the node loop's futures mirror asyncio's: cancellation is a BaseException so that
    # ``except Exception`` in user callbacks never swallows it; misuse of a future is a programming error
    "ninjemys.net.loop.CancelledError": "asyncio.CancelledError's contract (a BaseException)",
    "ninjemys.net.loop.InvalidStateError": "asyncio.InvalidStateError's contract (a programming error)",
    # private control-flow signals, raised and caught within one module, never seen by a caller
    "ninjemys.master.store.Superseded": "caught by master/server.py, answered as a -1 code",
    "ninjemys.master.server._Invalid": "caught in the same module, answered as a -1 code",
    "ninjemys.paramyaml_emit._Unsupported": "caught in the same module (falls back to PyYAML)",
}

#: folders that are package data, not code: ROS package resource folders that ship with ninjemys
DATA_PACKAGES = ("packages/share/",)


def _modules() -> list[str]:
    names = []
    for info in pkgutil.walk_packages(ninjemys.__path__, "ninjemys."):
        if info.name.startswith("ninjemys.packages.share."):
            continue
        names.append(info.name)
    return names


def _exception_classes() -> dict[str, type]:
    found: dict[str, type] = {}
    for name in _modules():
        module = importlib.import_module(name)
        for _, obj in inspect.getmembers(module, inspect.isclass):
            if obj.__module__ == name and issubclass(obj, BaseException):
                found[f"{name}.{obj.__qualname__}"] = obj
    return found


def test_every_exception_class_derives_from_ninjemys_error() -> None:
    classes = _exception_classes()
    assert len(classes) > 30, "the walk found too few exception classes: is it looking in the right place?"
    stray = sorted(
        name for name, cls in classes.items() if not issubclass(cls, NinjemysError) and name not in OUTSIDE
    )
    assert not stray, f"exception classes outside ninjemys.errors.NinjemysError: {stray}"
    gone = sorted(set(OUTSIDE) - set(classes))
    assert not gone, f"OUTSIDE names classes that no longer exist: {gone}"


def test_the_wing_errors_keep_value_error_where_callers_catch_it() -> None:
    from ninjemys.bridge.convert import ConversionError
    from ninjemys.nav.planner import PlanError
    from ninjemys.sim.simcore import SpawnError
    from ninjemys.sim.world import TurtleError

    for cls in (TurtleError, SpawnError, PlanError, ConversionError):
        assert issubclass(cls, NinjemysError) and issubclass(cls, ValueError), cls


def test_every_package_has_a_docstring_face() -> None:
    faceless = []
    for init in sorted(PACKAGE_ROOT.rglob("__init__.py")):
        rel = init.relative_to(PACKAGE_ROOT).as_posix()
        if "__pycache__" in rel or rel.startswith(DATA_PACKAGES):
            continue
        doc = ast.get_docstring(ast.parse(init.read_text(encoding="utf-8")))
        if not doc or len(doc.split()) < 8:
            faceless.append(f"src/ninjemys/{rel}")
    assert not faceless, f"packages without a docstring saying what they are for: {faceless}"

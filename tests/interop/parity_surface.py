"""Print the public surface of one ROS 1 Python package as JSON, to compare ours with Debian's.

Run under either interpreter: ``python parity_surface.py PACKAGE MODULE...``. It imports PACKAGE first
(recording which of its submodules that import alone makes reachable, as ``tf.transformations`` is), then each
MODULE, and describes every public name: classes with their bases and members, functions with their
signatures (names, kinds, defaults), constants with their values.
"""

from __future__ import annotations

import importlib
import inspect
import json
import sys
import types

#: private names programs use anyway (tf.transformations' axis tables and epsilon)
PRIVATE_KEPT = {"_AXES2TUPLE", "_TUPLE2AXES", "_NEXT_AXIS", "_EPS"}


def signature(obj):
    try:
        sig = inspect.signature(obj)
    except (TypeError, ValueError):
        return None  # C++ (Boost.Python) functions have none: compared by name
    return [
        [p.name, p.kind.name, None if p.default is inspect.Parameter.empty else repr(p.default)]
        for p in sig.parameters.values()
    ]


def value(v):
    if isinstance(v, float):
        return repr(float(v))
    if isinstance(v, (int, str, bool, type(None))):
        return repr(v)
    if isinstance(v, (tuple, list, dict, set, frozenset)) and len(repr(v)) < 5000:
        return repr(v)
    try:
        return repr(float(v))  # numpy scalars print differently across numpy versions
    except (TypeError, ValueError):
        return type(v).__name__


def member(cls, name):
    try:
        raw = inspect.getattr_static(cls, name)
    except AttributeError:
        raw = getattr(cls, name)
    if isinstance(raw, (staticmethod, classmethod)):
        return {"kind": "method", "sig": signature(getattr(cls, name))}
    if isinstance(raw, property):
        return {"kind": "property"}
    if callable(raw):
        return {"kind": "method", "sig": signature(raw)}
    return {"kind": "attr", "value": value(raw)}


def describe(v):
    if isinstance(v, types.ModuleType):
        return {"kind": "module", "name": v.__name__}
    if inspect.isclass(v):
        names = [n for n in dir(v) if not n.startswith("_") or n in ("__init__", "__call__")]
        return {
            "kind": "class",
            "module": getattr(v, "__module__", ""),
            "bases": [c.__name__ for c in v.__mro__[1:] if c is not object],
            "members": {n: member(v, n) for n in names},
        }
    if callable(v):
        return {"kind": "function", "sig": signature(v)}
    return {"kind": "const", "value": value(v)}


def main() -> None:
    package, modules = sys.argv[1], sys.argv[2:]
    out = {}
    pkg = importlib.import_module(package)
    children = {m.split(".")[1] for m in modules if m.count(".") == 1 and m.startswith(package + ".")}
    children |= {n for n, v in vars(pkg).items() if isinstance(v, types.ModuleType)}
    # what ``import PACKAGE`` alone lets a program reach (a lazy package's __getattr__ counts)
    out["<submodules>"] = sorted(
        n
        for n in children
        if isinstance(getattr(pkg, n, None), types.ModuleType)
        and getattr(pkg, n).__name__ == f"{package}.{n}"
    )
    for name in modules:
        try:
            mod = importlib.import_module(name)
        except Exception as exc:
            out[name] = {"<error>": f"{type(exc).__name__}: {exc}"}
            continue
        public = {n for n in dir(mod) if not n.startswith("_")} | (PRIVATE_KEPT & set(dir(mod)))
        out[name] = {n: describe(getattr(mod, n)) for n in sorted(public)}
    print(json.dumps(out, sort_keys=True))


if __name__ == "__main__":
    main()

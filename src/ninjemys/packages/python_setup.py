"""The Python packages a catkin package's setup.py declares (``packages=``, ``package_dir=``).

setup.py is read with :mod:`ast`, never executed: catkin's ``generate_distutils_setup(...)`` and a
plain ``setup(...)`` call both carry the two keywords as literals in every tutorial and real package.
"""

from __future__ import annotations

import ast
from pathlib import Path

from ninjemys.errors import PackageError


def python_packages(package_dir: Path) -> dict[str, Path]:
    """Python package name -> its source directory, from ``package_dir/setup.py``."""
    setup_py = package_dir / "setup.py"
    try:
        tree = ast.parse(setup_py.read_text(encoding="utf-8"), filename=str(setup_py))
    except OSError as exc:
        raise PackageError(f"{setup_py}: catkin_python_setup() needs a setup.py ({exc.strerror})") from None
    except SyntaxError as exc:
        raise PackageError(f"{setup_py}:{exc.lineno}: invalid Python: {exc.msg}") from None
    packages: list[str] = []
    dirs: dict[str, str] = {}
    for node in ast.walk(tree):
        if not isinstance(node, ast.Call):
            continue
        for kw in node.keywords:
            try:
                value = ast.literal_eval(kw.value)
            except ValueError:
                continue
            if kw.arg == "packages" and isinstance(value, list | tuple):
                packages.extend(str(p) for p in value)
            elif kw.arg == "package_dir" and isinstance(value, dict):
                dirs.update({str(k): str(v) for k, v in value.items()})
    result: dict[str, Path] = {}
    for name in packages:
        if name in dirs:
            result[name] = (package_dir / dirs[name]).resolve()
        else:
            base = package_dir / dirs.get("", "")
            result[name] = (base / name.replace(".", "/")).resolve()
    return result

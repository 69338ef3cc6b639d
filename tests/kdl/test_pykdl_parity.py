"""Our PyKDL and tf_conversions.posemath against Debian's (C++ PyKDL, python3-tf-conversions), run
side by side: the same numbers to 1e-12 on random inputs, the same printing and the same error types."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

HERE = Path(__file__).parent
REAL_PYTHON = "/usr/bin/python3"


def _run(python: str, script: str, ros1: bool) -> dict:
    env = dict(os.environ)
    if ros1:
        env.pop("PYTHONPATH", None)
        env["PYTHONNOUSERSITE"] = "1"
    done = subprocess.run(
        [python, str(HERE / script)], capture_output=True, text=True, timeout=120, env=env, cwd="/"
    )
    assert done.returncode == 0, done.stderr
    return json.loads(done.stdout)


def _close(path: str, a: object, b: object, problems: list[str]) -> None:
    if isinstance(a, dict):
        assert isinstance(b, dict) and sorted(a) == sorted(b), f"{path}: keys {sorted(b)} vs {sorted(a)}"
        for key in a:
            _close(f"{path}.{key}", a[key], b[key], problems)
    elif isinstance(a, list):
        assert isinstance(b, list) and len(a) == len(b), f"{path}: {len(b)} items vs {len(a)}"
        for i, (x, y) in enumerate(zip(a, b, strict=True)):
            _close(f"{path}[{i}]", x, y, problems)
    elif isinstance(a, float) or isinstance(b, float):
        if abs(float(a) - float(b)) > 1e-12:  # type: ignore[arg-type]
            problems.append(f"{path}: ours {b} Debian's {a}")
    elif a != b:
        problems.append(f"{path}: ours {b!r} Debian's {a!r}")


def _compare(script: str) -> None:
    theirs = _run(REAL_PYTHON, script, ros1=True)
    ours = _run(sys.executable, script, ros1=False)
    problems: list[str] = []
    _close("", theirs, ours, problems)
    assert not problems, "\n".join(problems[:20])


@pytest.mark.ros1
def test_pykdl_matches_debian_pykdl() -> None:
    _compare("pykdl_probe.py")


@pytest.mark.ros1
def test_posemath_matches_debian_tf_conversions() -> None:
    _compare("posemath_probe.py")


def test_pykdl_is_ours_and_pure_python() -> None:
    import PyKDL

    assert PyKDL.__file__.endswith("src/PyKDL/__init__.py")
    f = PyKDL.Frame(PyKDL.Rotation.RotZ(1.0), PyKDL.Vector(1, 2, 3))
    assert f * f.Inverse() == PyKDL.Frame.Identity()
    assert f.Inverse() * f == PyKDL.Frame()
    with pytest.raises(IndexError, match="Frame index out of range"):
        f[3, 0]

"""Every data file under src/ ships in the wheel: `pip install ninjemys` must carry the launch files,
worlds, maps, interfaces and browser assets, not only the Python modules.

setuptools only copies non-Python files that match ``[tool.setuptools.package-data]``; a new kind of
file (say a ``.cfg`` or ``.stl``) would silently be left out of the wheel while every test from the
source tree still passes. This test names such a file before a user finds it missing.
"""

from __future__ import annotations

import fnmatch
import subprocess
import tomllib
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]


def test_every_tracked_data_file_matches_a_package_data_pattern() -> None:
    try:
        listed = subprocess.run(
            ["git", "ls-files", "src"], cwd=ROOT, capture_output=True, text=True, check=True
        ).stdout.split()
    except (OSError, subprocess.CalledProcessError):
        pytest.skip("not a git checkout")
    config = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))
    patterns = [p for group in config["tool"]["setuptools"]["package-data"].values() for p in group]
    data = [f for f in listed if not f.endswith(".py")]
    assert len(data) > 100  # launch files, worlds, maps, .msg/.srv/.action, the web assets
    left_out = [f for f in data if not any(fnmatch.fnmatch(Path(f).name, p) for p in patterns)]
    assert not left_out, f"not shipped in the wheel (add a pattern to pyproject.toml): {left_out}"

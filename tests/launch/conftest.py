"""Fixtures for launch tests: the corpus packages on ROS_PACKAGE_PATH."""

from __future__ import annotations

from pathlib import Path

import pytest

DATA = Path(__file__).parent / "data"
PKGS = DATA / "pkgs"


@pytest.fixture
def corpus_env(monkeypatch: pytest.MonkeyPatch) -> dict[str, str]:
    """The environment both roslaunch implementations see for the corpus."""
    env = {
        "ROS_PACKAGE_PATH": str(PKGS),
        "NJ_CORPUS_USER": "tester",
        "ROS_MASTER_URI": "http://localhost:11311",
    }
    for key, value in env.items():
        monkeypatch.setenv(key, value)
    monkeypatch.delenv("NJ_CORPUS_HOME", raising=False)
    monkeypatch.delenv("CMAKE_PREFIX_PATH", raising=False)
    return env

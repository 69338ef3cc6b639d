"""Fixtures of the IDL tests: the fixture interface package h1_test_msgs on ROS_PACKAGE_PATH."""

from __future__ import annotations

from pathlib import Path

import pytest
from idl_fixtures import FIXTURE_SRC


@pytest.fixture
def fixture_path(monkeypatch: pytest.MonkeyPatch) -> Path:
    """Put the fixture package h1_test_msgs on ROS_PACKAGE_PATH (the search cache is keyed by it)."""
    monkeypatch.setenv("ROS_PACKAGE_PATH", str(FIXTURE_SRC))
    return FIXTURE_SRC

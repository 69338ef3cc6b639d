"""Shared fixtures. Tests that start processes use free ports and tear everything down."""

from __future__ import annotations

import os

import pytest

from ninjemys.testing import free_port, have_ros1


def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    if have_ros1():
        return
    skip = pytest.mark.skip(reason="Debian's ROS 1 is not installed (make test installs it)")
    for item in items:
        if "ros1" in item.keywords:
            item.add_marker(skip)


@pytest.fixture
def port() -> int:
    return free_port()


@pytest.fixture(autouse=True)
def _isolated_ros_home(tmp_path_factory: pytest.TempPathFactory, monkeypatch: pytest.MonkeyPatch) -> None:
    """Every test gets its own ROS_HOME so logs never land in the user's ~/.ros."""
    home = tmp_path_factory.mktemp("ros_home")
    monkeypatch.setenv("ROS_HOME", str(home))
    monkeypatch.delenv("ROS_MASTER_URI", raising=False)
    monkeypatch.delenv("ROS_NAMESPACE", raising=False)
    monkeypatch.setenv("ROS_HOSTNAME", os.environ.get("NINJEMYS_TEST_HOSTNAME", "localhost"))

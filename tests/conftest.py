"""Shared fixtures. Tests that start processes use free ports and tear everything down."""

from __future__ import annotations

import os

import pytest

from ninjemys.testing import free_port, have_ros1


def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    _long_files_first(items)
    if have_ros1():
        return
    skip = pytest.mark.skip(reason="Debian's ROS 1 is not installed (make test installs it)")
    for item in items:
        if "ros1" in item.keywords:
            item.add_marker(skip)


def _long_files_first(items: list[pytest.Item]) -> None:
    """Files holding a ``slow`` test first, then by test count (xdist's own loadfile order, which
    ``make test`` turns off with ``--no-loadscope-reorder`` to use this one). By count alone, the
    navigation sessions' file (10 minutes, few tests) started last and ran on one worker while the
    other sat idle. The sort is stable: a file's tests keep their order (its sessions rely on it)."""
    slow = {item.path for item in items if item.get_closest_marker("slow") is not None}
    count: dict[object, int] = {}
    for item in items:
        count[item.path] = count.get(item.path, 0) + 1
    items.sort(key=lambda item: (item.path not in slow, -count[item.path]))


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

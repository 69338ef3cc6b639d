"""Fixtures of the interface oracle tests: one genpy oracle process per test session (per xdist worker)."""

from __future__ import annotations

from collections.abc import Iterator

import pytest
from iface_oracle import GenpyOracle

from ninjemys.testing import have_ros1


@pytest.fixture(scope="session")
def genpy_oracle() -> Iterator[GenpyOracle]:
    if not have_ros1():
        pytest.skip("Debian's ROS 1 is not installed")
    oracle = GenpyOracle()
    try:
        yield oracle
    finally:
        oracle.close()

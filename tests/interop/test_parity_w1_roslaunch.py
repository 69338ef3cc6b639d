"""roslaunch's Python API against Debian's: rlutil (run id from the master, launch argument
resolution and its errors), ROSLaunchParent launching a file with arguments and an XML string
(parameters set, nodes up, gone after shutdown), scriptapi.ROSLaunch launching and stopping a node,
core.Node's checks and attributes."""

from __future__ import annotations

import pytest
from test_parity_behaviour import compare

pytestmark = pytest.mark.ros1


def test_roslaunch_api_matches_ros1() -> None:
    compare("parity_w1_roslaunch_peer.py", with_master=True)

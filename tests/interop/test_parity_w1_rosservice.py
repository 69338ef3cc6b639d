"""rosservice's and rosmsg's Python APIs against Debian's: service listings, probed types, classes,
call_service (good arguments, ROS 1's error texts for bad ones, a raising handler, no such service,
called inside a node), and definitions/listings as rosmsg gives them."""

from __future__ import annotations

import pytest
from test_parity_behaviour import compare

pytestmark = pytest.mark.ros1


def test_rosservice_and_rosmsg_apis_match_ros1() -> None:
    compare("parity_w1_rosservice_peer.py", with_master=True)

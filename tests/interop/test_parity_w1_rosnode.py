"""rosnode's Python API against Debian's: names, URIs, ping of a live, an unknown and a dead node,
the info texts, kill_nodes on a node process, cleanup_master_blacklist."""

from __future__ import annotations

import pytest
from test_parity_behaviour import compare

pytestmark = pytest.mark.ros1


def test_rosnode_api_matches_ros1() -> None:
    compare("parity_w1_rosnode_peer.py", with_master=True)

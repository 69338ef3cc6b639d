"""rostopic's Python API against Debian's in a running node: get_topic_type/get_topic_class (fields
inside topics), msgevalgen and its slice errors, get_info_text, listings, and the hz/bw/delay meters."""

from __future__ import annotations

import pytest
from test_parity_behaviour import compare

pytestmark = pytest.mark.ros1


def test_rostopic_api_matches_ros1() -> None:
    compare("parity_w1_rostopic_peer.py", with_master=True)

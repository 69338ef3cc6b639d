"""rosgraph against Debian's: names, the Master handle (answers, MasterError texts, a dead master's
socket error), network helpers and the handshake codec, by one peer script run under both interpreters."""

from __future__ import annotations

import pytest
from test_parity_behaviour import compare

pytestmark = pytest.mark.ros1


def test_rosgraph_matches_ros1() -> None:
    compare("parity_w1_rosgraph_peer.py", with_master=True)

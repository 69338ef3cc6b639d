"""genpy against Debian's: genpy.Message/Time/Duration identities, fill_message_args (results and
MessageException texts), check_type, strify_message, the errors messages raise, and genpy.dynamic.generate_dynamic (classes from a full
text: md5sums, wire bytes, constants)."""

from __future__ import annotations

import pytest
from test_parity_behaviour import compare

pytestmark = pytest.mark.ros1


def test_genpy_matches_ros1() -> None:
    compare("parity_w1_genpy_peer.py")

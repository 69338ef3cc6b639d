"""``ninjemys.node.run.start_node``: the name a node takes from the command line, anonymous or not."""

from __future__ import annotations

import re

from ninjemys.master.core import MasterThread
from ninjemys.node.run import start_node


def test_anonymous_tools_get_rospy_style_unique_names_and_name_remapping_wins():
    with MasterThread() as uri:
        plain = start_node("tf_echo", [f"__master:={uri}"])
        one = start_node("tf_echo", [f"__master:={uri}"], anonymous=True)
        two = start_node("tf_echo", [f"__master:={uri}"], anonymous=True)
        named = start_node("tf_echo", [f"__master:={uri}", "__name:=echo"], anonymous=True)
        try:
            assert plain.name == "/tf_echo"
            assert re.fullmatch(r"/tf_echo_\d+_\d+", one.name), one.name
            assert one.name != two.name  # two tools side by side do not kick each other off the master
            assert named.name == "/echo"  # __name:= cancels anonymous, as in rospy
        finally:
            for node in (plain, one, two, named):
                node.shutdown("test")

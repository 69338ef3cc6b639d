"""How the actionlib facade reaches rospy's process: the core node ``rospy.init_node`` made.

The cores take their clock (ROS time, simulated under /use_sim_time) and their log (console, log
file and /rosout) from that node, so a facade object behaves like the rest of the rospy program.
"""

from __future__ import annotations

import rospy.core

TYPE_CHECKING = False
if TYPE_CHECKING:
    from typing import Any


def node() -> Any:
    """The core Node of ``rospy.init_node`` (ROSInitException before it)."""
    return rospy.core.process_node()

"""rospy_tutorials listener: log every String received on ``chatter``."""

from __future__ import annotations

import sys
from typing import Any

from ninjemys.tutorials import node_main


def _heard(message: Any) -> None:
    import rospy

    rospy.loginfo(rospy.get_caller_id() + "I heard %s", message.data)


@node_main
def main(argv: list[str] | None = None) -> int:
    import rospy
    from std_msgs.msg import String

    if argv is not None:
        sys.argv[1:] = argv
    rospy.init_node("listener", anonymous=True)
    rospy.Subscriber("chatter", String, _heard)
    rospy.spin()
    return 0


if __name__ == "__main__":
    sys.exit(main())

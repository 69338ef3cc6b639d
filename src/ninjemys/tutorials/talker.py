"""rospy_tutorials talker: publish "hello world <time>" on ``chatter`` at 10 Hz."""

from __future__ import annotations

import sys

from ninjemys.tutorials import node_main


@node_main
def main(argv: list[str] | None = None) -> int:
    import rospy
    from std_msgs.msg import String

    if argv is not None:
        sys.argv[1:] = argv
    publisher = rospy.Publisher("chatter", String, queue_size=10)
    rospy.init_node("talker", anonymous=True)
    rate = rospy.Rate(10)
    try:
        while not rospy.is_shutdown():
            text = "hello world %s" % rospy.get_time()
            rospy.loginfo(text)
            publisher.publish(text)
            rate.sleep()
    except rospy.ROSInterruptException:
        pass
    return 0


if __name__ == "__main__":
    sys.exit(main())

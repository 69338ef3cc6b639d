"""actionlib_tutorials gen_numbers.py: publish ``random_number`` (Float32), normal around 5, at 20 Hz.

The number source of the averaging tutorial (node ``random_number_generator``).
"""

from __future__ import annotations

import random
import sys

from ninjemys.tutorials import node_main


@node_main
def main(argv: list[str] | None = None) -> int:
    import rospy
    from std_msgs.msg import Float32

    if argv is not None:
        sys.argv[1:] = argv
    publisher = rospy.Publisher("random_number", Float32, queue_size=10)
    rospy.init_node("random_number_generator", log_level=rospy.INFO)
    rospy.loginfo("Generating random numbers")
    try:
        while not rospy.is_shutdown():
            publisher.publish(Float32(random.normalvariate(5, 1)))
            rospy.sleep(0.05)
    except rospy.ROSInterruptException:
        pass
    return 0


if __name__ == "__main__":
    sys.exit(main())

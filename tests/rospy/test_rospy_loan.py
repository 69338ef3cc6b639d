"""``rospy.Publisher.loan``: rospy-API code reaches ninjemys' loaned messages without the private
core publisher, and a loaned image reaches a same-host rospy listener whole (over SHMROS)."""

from __future__ import annotations

TALKER = """
import rospy
from sensor_msgs.msg import Image
rospy.init_node("loaner")
pub = rospy.Publisher("img", Image, queue_size=1)
while pub.get_num_connections() == 0 and not rospy.is_shutdown():
    rospy.sleep(0.02)
rate = rospy.Rate(20)
i = 0
while not rospy.is_shutdown():
    with pub.loan(640 * 480 * 3, height=480, width=640, encoding="rgb8", step=640 * 3) as msg:
        msg.data[:] = i % 256
        pub.publish(msg)
    i += 1
    rate.sleep()
"""

LISTENER = """
import rospy
from sensor_msgs.msg import Image
def heard(msg):
    data = bytes(msg.data)
    print("got %d %dx%d %s uniform=%s" % (len(data), msg.width, msg.height, msg.encoding, len(set(data)) == 1), flush=True)
rospy.init_node("viewer")
rospy.Subscriber("img", Image, heard, queue_size=1)
rospy.spin()
"""


def test_a_rospy_publisher_loans_an_image_that_a_rospy_listener_gets_whole(run_node) -> None:  # noqa: ANN001
    listener = run_node(LISTENER)
    run_node(TALKER)
    for _ in range(3):
        listener.wait_for(r"^got 921600 640x480 rgb8 uniform=True$")


def test_loan_before_init_node_says_so(run_node) -> None:  # noqa: ANN001
    proc = run_node(
        "import rospy\nfrom sensor_msgs.msg import Image\n"
        "pub = rospy.Publisher('img', Image, queue_size=1)\n"
        "try:\n    pub.loan(100)\nexcept rospy.ROSException as exc:\n    print('refused:', exc, flush=True)\n"
    )
    proc.wait_for(r"^refused: ROS node has not been initialized yet")

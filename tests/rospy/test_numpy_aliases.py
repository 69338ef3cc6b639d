"""Node code of Noetic's era uses numpy names numpy has removed since (``np.int``, ``np.float``,
``np.NaN``, ``np.float_`` ...): it runs on Noetic's numpy 1.17. A rospy node here gets them back when
it starts, as that numpy had them, so a lane detector that sizes its windows with ``np.int`` in a
callback runs unchanged (ROBOTIS' TurtleBot3 AutoRace ``detect_lane`` did not)."""

from __future__ import annotations

LANE_NODE = """
import numpy as np
import rospy
from std_msgs.msg import Float64, Int32

def on_width(msg):
    windows = np.int(msg.data / 20)
    margin = np.float(msg.data) * 0.1
    print("windows", windows, type(windows).__name__, "margin", margin, flush=True)
    print("nan", np.isnan(np.NaN), "inf", np.Inf == np.inf, "float_", np.float_ is np.float64, flush=True)
    print("bool", np.bool(1), "object", np.zeros(2, dtype=np.object).dtype, flush=True)
    rospy.signal_shutdown("done")

rospy.init_node("lane_width")
rospy.Subscriber("width", Int32, on_width)
print("ready", flush=True)
rospy.spin()
"""

NO_NUMPY = """
import sys
import rospy
rospy.init_node("plain")
print("numpy imported:", "numpy" in sys.modules, flush=True)
"""


def test_a_callback_using_removed_numpy_names_runs_as_on_noetic(run_node) -> None:
    node = run_node(LANE_NODE)
    node.wait_for("^ready$")
    pub = run_node(
        "import rospy\nfrom std_msgs.msg import Int32\nrospy.init_node('pub')\n"
        "p = rospy.Publisher('width', Int32, queue_size=1, latch=True)\np.publish(Int32(320))\nrospy.spin()\n"
    )
    node.wait_for(r"^windows 16 int margin 32\.0$")
    node.wait_for(r"^nan True inf True float_ True$")
    node.wait_for(r"^bool True object object$")
    assert node.wait(10) == 0
    pub.interrupt()


def test_a_node_without_numpy_does_not_import_it(run_node) -> None:
    node = run_node(NO_NUMPY)
    node.wait_for("^numpy imported: False$")

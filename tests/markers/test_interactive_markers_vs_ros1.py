"""interactive_markers' Python server and menu against Debian's python3-interactive-markers (Noetic's).

The same server script (a marker with a control and a callback, a menu with a sub-entry, a checkbox
and a hidden entry, poses set before and after applyChanges) runs under real rospy and under ours;
one driver of ours plays rviz: it reads update_full and update, sends pose and menu feedback (plus a
second client's feedback, which the server must ignore) and reports what it saw. Both runs must
report the same.

One difference is on purpose: Noetic's ``MenuHandler.apply`` on a marker the server does not have
raises KeyError (it removes the name from a set it was never added to); ours returns False, as its
documentation and the C++ MenuHandler say."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from ninjemys.testing import ROS1_PYTHON, have_ros1, kill_tree, ros1_env, run_master

SERVER = r"""
import sys
import rospy
from interactive_markers.interactive_marker_server import *
from interactive_markers.menu_handler import *
from geometry_msgs.msg import Pose
from std_msgs.msg import String
from visualization_msgs.msg import InteractiveMarkerControl

rospy.init_node("im_server")
heard = rospy.Publisher("heard", String, queue_size=50)
server = InteractiveMarkerServer("controls")


def moved(fb):
    heard.publish(String("pose %s %s %.3f" % (fb.marker_name, fb.client_id, fb.pose.position.x)))
    server.applyChanges()


def chosen(fb):
    heard.publish(String("menu %d %s" % (fb.menu_entry_id, menu.getTitle(fb.menu_entry_id))))


marker = InteractiveMarker()
marker.header.frame_id = "base_link"
marker.name = "box"
marker.description = "a box"
marker.scale = 0.5
control = InteractiveMarkerControl()
control.name = "move_x"
control.orientation.w = 1.0
control.orientation.x = 1.0
control.interaction_mode = InteractiveMarkerControl.MOVE_AXIS
marker.controls.append(control)
server.insert(marker, moved)

menu = MenuHandler()
first = menu.insert("First", callback=chosen)
sub = menu.insert("Sub", parent=first, callback=chosen)
check = menu.insert("Check", callback=chosen)
menu.setCheckState(check, MenuHandler.UNCHECKED)
hidden = menu.insert("Hidden", callback=chosen)
menu.setVisible(hidden, False)
print("orphan", menu.insert("Orphan", parent=99))
print("apply", menu.apply(server, "box"))

pose = Pose()
pose.position.x = 2.0
pose.orientation.w = 1.0
print("setPose pending", server.setPose("box", pose))
print("erase missing", server.erase("nope"))
server.applyChanges()
print("setPose applied", server.setPose("box", pose))
print("get", server.get("box").pose.position.x, server.get("nope"))
menu.setCheckState(check, MenuHandler.CHECKED)
print("reApply", menu.reApply(server))
server.applyChanges()
print("done", flush=True)
rospy.spin()
"""

DRIVER = r"""
import json, sys, time
import rospy
from std_msgs.msg import String
from visualization_msgs.msg import InteractiveMarkerFeedback, InteractiveMarkerInit, InteractiveMarkerUpdate

rospy.init_node("im_driver")
fulls, updates, heard = [], [], []
rospy.Subscriber("controls/update_full", InteractiveMarkerInit, fulls.append)
rospy.Subscriber("controls/update", InteractiveMarkerUpdate, updates.append)
rospy.Subscriber("heard", String, lambda m: heard.append(m.data))
feedback = rospy.Publisher("controls/feedback", InteractiveMarkerFeedback, queue_size=10)


def wait(what, test):
    deadline = time.time() + 60
    while not test():
        if time.time() > deadline:
            print(json.dumps({"timeout": what, "heard": heard}))
            sys.exit(1)
        time.sleep(0.05)


wait("the menu applied", lambda: fulls and fulls[-1].markers and fulls[-1].markers[0].menu_entries
     and fulls[-1].markers[0].menu_entries[-1].title.startswith("[x]"))
wait("a feedback subscriber", lambda: feedback.get_num_connections() > 0)
time.sleep(1.0)

def send(event, client, x=0.0, entry=0):
    fb = InteractiveMarkerFeedback(client_id=client, marker_name="box", control_name="move_x", event_type=event)
    fb.header.frame_id = "base_link"
    fb.pose.position.x = x
    fb.pose.orientation.w = 1.0
    fb.menu_entry_id = entry
    feedback.publish(fb)


send(InteractiveMarkerFeedback.POSE_UPDATE, "/rviz/a", x=3.0)
wait("the pose feedback", lambda: len(heard) >= 1)
send(InteractiveMarkerFeedback.POSE_UPDATE, "/other", x=9.0)  # a second client within 1 s: ignored
send(InteractiveMarkerFeedback.MENU_SELECT, "/rviz/a", entry=2)
wait("the menu feedback", lambda: len(heard) >= 2)
wait("the moved marker", lambda: fulls[-1].markers[0].pose.position.x == 3.0)
time.sleep(1.0)
last = fulls[-1]
box = last.markers[0]
kinds = [u.type for u in updates]
real = [u for u in updates if u.type == InteractiveMarkerUpdate.UPDATE]
print(json.dumps({
    "server_id": last.server_id,
    "seq": [last.seq_num, real[-1].seq_num] if real else None,
    "full": [box.name, box.description, box.header.frame_id, box.pose.position.x, box.scale,
             [c.name for c in box.controls]],
    "menu": [[e.id, e.parent_id, e.title, e.command_type] for e in box.menu_entries],
    "keep_alive": InteractiveMarkerUpdate.KEEP_ALIVE in kinds,
    "last_update": [[m.name for m in real[-1].markers], [(p.name, p.pose.position.x) for p in real[-1].poses],
                    list(real[-1].erases)] if real else None,
    "heard": heard,
}, sort_keys=True))
"""

pytestmark = [
    pytest.mark.ros1,
    pytest.mark.skipif(
        not (have_ros1() and Path("/usr/lib/python3/dist-packages/interactive_markers").is_dir()),
        reason="needs Debian's ROS 1 and python3-interactive-markers",
    ),
]


def _run(server_cmd: list[str], server_env: dict[str, str], uri: str, tmp: Path) -> tuple[str, dict]:
    server = subprocess.Popen(
        [*server_cmd, str(tmp / "server.py")],
        env=server_env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, start_new_session=True,
    )  # fmt: skip
    try:
        driver = subprocess.run(
            [sys.executable, str(tmp / "driver.py")],
            env=dict(os.environ, ROS_MASTER_URI=uri, ROS_HOSTNAME="localhost"),
            capture_output=True, text=True, timeout=120, check=False,
        )  # fmt: skip
    finally:
        kill_tree(server)
    out = server.stdout.read() if server.stdout else ""
    assert driver.returncode == 0, driver.stdout + driver.stderr + out
    lines = [line for line in out.splitlines() if line.split(" ")[0] in SERVER]
    return "\n".join(lines), json.loads(driver.stdout.strip().splitlines()[-1])


def test_server_and_menu_behave_as_noetics(tmp_path: Path) -> None:
    (tmp_path / "server.py").write_text(SERVER)
    (tmp_path / "driver.py").write_text(DRIVER)
    results = {}
    with run_master() as uri:
        results["ros1"] = _run([ROS1_PYTHON], ros1_env(uri), uri, tmp_path)
    with run_master() as uri:
        ours_env = dict(os.environ, ROS_MASTER_URI=uri, ROS_HOSTNAME="localhost")
        results["ours"] = _run([sys.executable], ours_env, uri, tmp_path)
    printed, seen = results["ours"]
    assert results["ours"] == results["ros1"]
    assert "setPose pending False" in printed and "apply True" in printed
    assert seen["menu"] == [[1, 0, "First", 0], [2, 1, "Sub", 0], [3, 0, "[x] Check", 0]]
    assert seen["heard"] == ["pose box /rviz/a 3.000", "menu 2 Sub"]
    assert seen["server_id"] == "/im_server" and seen["keep_alive"]


def test_menu_apply_to_a_missing_marker_is_false() -> None:
    from interactive_markers.menu_handler import MenuHandler

    class NoMarkers:
        def get(self, name: str) -> None:
            return None

    menu = MenuHandler()
    menu.insert("Only")
    assert menu.apply(NoMarkers(), "nope") is False
    assert menu.reApply(NoMarkers()) is True

"""What ninjemys ships: every message, service and action type, read straight from the interface files.

The tests enumerate types from the files (not from the loader) so a type the loader forgot to expose
still shows up, and fails, instead of silently dropping out of the comparison.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import ninjemys

INTERFACES = Path(ninjemys.__file__).parent / "interfaces"

#: the 17 packages of the Foundation issue, point 5, and the interface packages of wave 2
SHIPPED_PACKAGES = (
    "std_msgs",
    "std_srvs",
    "geometry_msgs",
    "sensor_msgs",
    "nav_msgs",
    "rosgraph_msgs",
    "actionlib_msgs",
    "tf2_msgs",
    "diagnostic_msgs",
    "visualization_msgs",
    "trajectory_msgs",
    "shape_msgs",
    "stereo_msgs",
    "roscpp",
    "turtlesim",
    "rospy_tutorials",
    "actionlib_tutorials",
    # wave 2 (issue 13, point 6): what actionlib, navigation and controllers need
    "actionlib",
    "move_base_msgs",
    "map_msgs",
    "control_msgs",
    "gazebo_msgs",
    "tf",
    "dynamic_reconfigure",
    # wave 2 (issue 16): the WebSocket gateway's rosapi and tf2_web_republisher
    "rosapi",
    "tf2_web_republisher",
    # wave 3: device drivers (issue 24)
    "realsense2_camera",
    # issue 21 item 7: the long tail course code imports (smach's introspection, aruco_detect's fiducials)
    "smach_msgs",
    "fiducial_msgs",
    "rosserial_msgs",
    # wave 3: ros_control's controller_manager (issue 23)
    "controller_manager_msgs",
)

#: packages Debian's ROS 1 lacks; their facts are checked against published md5sums instead
NOT_IN_DEBIAN = frozenset(
    {
        "turtlesim",
        "rospy_tutorials",
        "actionlib_tutorials",
        "control_msgs",
        "gazebo_msgs",
        "rosapi",
        "tf2_web_republisher",
        "realsense2_camera",
        "smach_msgs",
        "fiducial_msgs",
        "rosserial_msgs",
        "controller_manager_msgs",
    }
)

#: the messages actionlib generates from one ``Foo.action``
ACTION_SUFFIXES = ("Action", "ActionGoal", "ActionResult", "ActionFeedback", "Goal", "Result", "Feedback")


@dataclass(frozen=True)
class Inventory:
    messages: tuple[str, ...]  # every message type, including the 7 generated per action
    services: tuple[str, ...]
    actions: tuple[str, ...]

    @property
    def service_parts(self) -> tuple[str, ...]:
        """``pkg/FooRequest`` and ``pkg/FooResponse`` of every service (messages in their own right)."""
        return tuple(f"{s}{part}" for s in self.services for part in ("Request", "Response"))

    @property
    def all_message_like(self) -> tuple[str, ...]:
        """Everything that has a message class: messages plus service requests and responses."""
        return self.messages + self.service_parts


def _names(pkg_dir: Path, sub: str, ext: str) -> list[str]:
    folder = pkg_dir / sub
    if not folder.is_dir():
        return []
    return sorted(f"{pkg_dir.name}/{p.stem}" for p in folder.glob(f"*.{ext}"))


def inventory() -> Inventory:
    messages: list[str] = []
    services: list[str] = []
    actions: list[str] = []
    for pkg in SHIPPED_PACKAGES:
        pkg_dir = INTERFACES / pkg
        messages += _names(pkg_dir, "msg", "msg")
        services += _names(pkg_dir, "srv", "srv")
        for action in _names(pkg_dir, "action", "action"):
            actions.append(action)
            messages += [f"{action}{suffix}" for suffix in ACTION_SUFFIXES]
    return Inventory(tuple(messages), tuple(services), tuple(actions))


def package_of(type_name: str) -> str:
    return type_name.split("/", 1)[0]

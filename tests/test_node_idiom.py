"""One node idiom from core to apps: the in-house nodes of the apps (the gateway, the simulators, the
navigation stack, the drivers, the web tools) and of the command-line tools (the tf tools, buffer_server,
the rostopic/rosservice helpers) are core ``Node``s run by ``ninjemys.node.run``; none imports rospy or
the client-library facades built on it (tf, tf2_ros, actionlib), which stay for the tutorials and for
users' programs (checked with ``ast``: every import form counts, as in test_layering)."""

from __future__ import annotations

import ast
from pathlib import Path

SRC = Path(__file__).resolve().parents[1] / "src" / "ninjemys"
APPS = ("bridge", "sim", "nav", "drivers", "web", "robot", "image_transport", "tools")
#: ROS 1's Python client library and the facades that run on its process node
FACADES = ("rospy", "tf", "tf2_ros", "actionlib")


def rospy_imports(root: Path) -> list[str]:
    """``file:line`` of every import of rospy or a facade on it (or a submodule) under ``root``."""
    found = []
    for path in sorted(root.rglob("*.py")):
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            names: list[str] = []
            if isinstance(node, ast.Import):
                names = [alias.name for alias in node.names]
            elif isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
                names = [node.module]
            found += [f"{path.relative_to(SRC)}:{node.lineno}" for n in names if n.split(".")[0] in FACADES]
    return found


#: modules that are rospy programs on purpose, with the reason
EXEMPT = {
    # rostest's stock hztest is a unittest case that rostest.rosrun runs and reports as JUnit XML: the
    # rostest facade that runs it is built on rospy, as in ROS 1
    "tools/hztest.py",
    # rostest's publishtest, paramtest and advertisetest: unittest cases run by rostest.rosrun, as hztest
    "tools/rostest_nodes.py",
}


def test_no_in_house_app_node_goes_through_rospy():
    offenders = [
        hit for app in APPS for hit in rospy_imports(SRC / app) if hit.rsplit(":", 1)[0] not in EXEMPT
    ]
    assert offenders == [], "in-house nodes use ninjemys.node.run and the core Node: " + ", ".join(offenders)


def test_the_check_sees_rospy_imports():
    assert rospy_imports(SRC / "tutorials"), "the tutorials are rospy programs: the scan must find them"

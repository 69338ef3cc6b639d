"""``URDF.from_parameter_server()`` (Noetic's urdf_parser_py) against our master, before and after
init_node, whichever of rospy and urdf_parser_py is imported first."""

from __future__ import annotations

import subprocess
import sys

import pytest

ROBOT = """<robot name="parity_bot">
  <link name="base"/><link name="arm"/>
  <joint name="shoulder" type="revolute"><parent link="base"/><child link="arm"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
</robot>"""

SET = f"import rosgraph; rosgraph.Master('/setter').setParam('/robot_description', {ROBOT!r})\n"

SCRIPTS = {
    "rospy_first_before_init": """
import rospy
from urdf_parser_py.urdf import URDF
robot = URDF.from_parameter_server()
print(robot.name, [j.name for j in robot.joints], robot.get_root())
""",
    "urdf_first_after_init": """
from urdf_parser_py.urdf import URDF
import rospy
rospy.init_node("urdf_reader", disable_signals=True)
robot = URDF.from_parameter_server("robot_description")
print(robot.name, [j.name for j in robot.joints], robot.get_root())
rospy.signal_shutdown("done")
""",
    "missing_key": """
import rospy
from urdf_parser_py.urdf import URDF
try:
    URDF.from_parameter_server("/no_such_description")
except KeyError as exc:
    print("KeyError", exc)
""",
}


@pytest.mark.parametrize("name", sorted(SCRIPTS))
def test_urdf_from_parameter_server(name: str, node_env: dict[str, str]) -> None:
    subprocess.run([sys.executable, "-c", SET], env=node_env, check=True, timeout=60)
    done = subprocess.run(
        [sys.executable, "-c", SCRIPTS[name]], env=node_env, capture_output=True, text=True, timeout=60
    )
    assert done.returncode == 0, done.stderr
    if name == "missing_key":
        assert done.stdout.strip() == "KeyError '/no_such_description'"
    else:
        assert done.stdout.strip() == "parity_bot ['shoulder'] base"

"""Helpers for the Gazebo-names tests: genpy classes of our gazebo_msgs for Debian's tools (Debian
packages no gazebo_msgs), a roslaunch process with its log, and a small two-wheeled URDF."""

from __future__ import annotations

import os
import subprocess
import time
from pathlib import Path

from ninjemys.idl.search import SHIPPED_ROOT as _SHIPPED
from ninjemys.testing import ROS1_PYTHON, kill_tree

SHIPPED_ROOT = Path(_SHIPPED)


def two_wheel_urdf(name: str, extra: str = "") -> str:
    """A two-wheeled robot as the maker's description has it, with a diff drive plugin: its root link
    at the wheels' axles, the wheels (radius 5 cm) 2 cm lower than the root, so standing on the floor
    the root is 7 cm up; ``extra`` holds further ``<gazebo>`` blocks."""
    return f"""<robot name="{name}">
  <link name="base_link"><collision><origin xyz="0 0 0.03"/><geometry><box size="0.2 0.16 0.06"/></geometry>
  </collision></link>
  <link name="wheel_left"><collision><geometry><cylinder radius="0.05" length="0.02"/></geometry></collision></link>
  <link name="wheel_right"><collision><geometry><cylinder radius="0.05" length="0.02"/></geometry></collision></link>
  <joint name="wheel_left_joint" type="continuous"><parent link="base_link"/><child link="wheel_left"/>
    <origin xyz="0 0.09 -0.02" rpy="-1.5708 0 0"/><axis xyz="0 0 1"/></joint>
  <joint name="wheel_right_joint" type="continuous"><parent link="base_link"/><child link="wheel_right"/>
    <origin xyz="0 -0.09 -0.02" rpy="-1.5708 0 0"/><axis xyz="0 0 1"/></joint>
  <gazebo><plugin name="dd" filename="libgazebo_ros_diff_drive.so">
    <leftJoint>wheel_left_joint</leftJoint><rightJoint>wheel_right_joint</rightJoint>
    <wheelSeparation>0.18</wheelSeparation><wheelDiameter>0.1</wheelDiameter>
    <robotBaseFrame>base_link</robotBaseFrame></plugin></gazebo>
  {extra}
</robot>"""


def genpy_gazebo_msgs(dest: Path) -> Path:
    """Debian's genpy generates Python classes from our gazebo_msgs definitions (what catkin_make of
    gazebo_msgs leaves on a ROS 1 machine); returns the directory to put on PYTHONPATH."""
    out = dest / "gazebo_msgs"
    include = [
        f"-I{pkg}:{SHIPPED_ROOT / pkg / 'msg'}"
        for pkg in ("gazebo_msgs", "geometry_msgs", "std_msgs", "trajectory_msgs", "sensor_msgs")
    ]
    # one genpy run per kind for all its files, then its __init__.py: a Python start-up per file (37)
    # took 52 s of wall time at load 23, and the module's fixture ran into pytest's 120 s timeout
    for kind, gen in (("msg", "genmsg_py.py"), ("srv", "gensrv_py.py")):
        files = sorted(str(p) for p in (SHIPPED_ROOT / "gazebo_msgs" / kind).iterdir())
        command = [ROS1_PYTHON, f"/usr/lib/genpy/{gen}", "-p", "gazebo_msgs", "-o", str(out / kind)]
        subprocess.run([*command, *include, *files], check=True, capture_output=True, timeout=120)
        subprocess.run([*command, "--initpy"], check=True, capture_output=True, timeout=120)
    (out / "__init__.py").write_text("")
    return dest


class Launched:
    """A process whose output goes to a log file; ``wait_for`` a line of it."""

    def __init__(self, cmd: list[str], env: dict[str, str], log: Path) -> None:
        self.log_path = log
        with open(log, "wb") as out:
            self.proc = subprocess.Popen(
                cmd,
                env=env,
                stdout=out,
                stderr=subprocess.STDOUT,
                stdin=subprocess.DEVNULL,
                start_new_session=True,
            )

    def log(self) -> str:
        return self.log_path.read_text(errors="replace")

    def wait_for(self, text: str, timeout: float = 30.0) -> str:
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            out = self.log()
            if text in out:
                return out
            if self.proc.poll() is not None:
                raise AssertionError(f"process exited ({self.proc.returncode}):\n{out}")
            time.sleep(0.05)
        raise AssertionError(f"never printed {text!r}:\n{self.log()}")

    def stop(self) -> None:
        if self.proc.poll() is None:
            try:
                os.killpg(self.proc.pid, 2)
                self.proc.wait(10)
            except (subprocess.TimeoutExpired, ProcessLookupError):
                kill_tree(self.proc)

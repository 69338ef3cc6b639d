"""xacro expansion of a 50-link description: ninjemys' ``xacro`` command vs the reference xacro.

Run: ``.venv/bin/python bench/xacro_expand.py`` (``--runs N``, default 10).

Debian has no xacro for ROS 1; the reference is the upstream ros/xacro project's own command line
(``xacro.main`` from PyPI, the code ROS ships), started the same way in the same run. Ours is that
library behind ninjemys' ``xacro`` command, with ``$(find)`` resolved through ROS_PACKAGE_PATH and
ninjemys' packages. The description is a package on ROS_PACKAGE_PATH: a macro per link (with a block
parameter), an include, a YAML file of dimensions, conditionals and math, 50 links and 49 joints.
Each run is a whole command (start-up plus expansion), the way ``roslaunch``'s ``command=`` runs it;
the output of both is checked to be the same bytes before anything is timed.
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

LINKS = 50
MACROS = """<?xml version="1.0"?>
<robot xmlns:xacro="http://www.ros.org/wiki/xacro">
  <xacro:macro name="segment" params="i parent length:=0.1 *axis">
    <link name="link_${i}">
      <visual><geometry><cylinder radius="${dims['radius']}" length="${length}"/></geometry></visual>
      <inertial><mass value="${dims['mass'] * length}"/>
        <inertia ixx="${length**2/12}" ixy="0" ixz="0" iyy="${length**2/12}" iyz="0" izz="0.001"/></inertial>
    </link>
    <joint name="joint_${i}" type="${'revolute' if i % 3 else 'continuous'}">
      <parent link="${parent}"/><child link="link_${i}"/>
      <origin xyz="0 0 ${length}" rpy="${radians(i * 7 % 90)} 0 ${pi / (i + 1)}"/>
      <xacro:insert_block name="axis"/>
      <xacro:if value="${i % 3}"><limit lower="${-pi}" upper="${pi}" effort="10" velocity="1"/></xacro:if>
    </joint>
  </xacro:macro>
</robot>
"""


def description(links: int) -> str:
    longer = ' length="0.2"'
    body = "".join(
        f'  <xacro:segment i="{i}" parent="link_{i - 1}"{longer if i % 2 else ""}>'
        f'<axis xyz="0 {i % 2} {1 - i % 2}"/></xacro:segment>\n'
        for i in range(1, links)
    )
    return (
        '<?xml version="1.0"?>\n<robot name="bench" xmlns:xacro="http://www.ros.org/wiki/xacro">\n'
        '  <xacro:arg name="gripper" default="true"/>\n'
        '  <xacro:property name="dims" value="${xacro.load_yaml(\'$(find bench_robot)/urdf/dims.yaml\')}"/>\n'
        '  <xacro:include filename="$(find bench_robot)/urdf/segment.xacro"/>\n'
        '  <link name="link_0"/>\n'
        f"{body}"
        '  <xacro:unless value="$(arg gripper)"><link name="no_gripper"/></xacro:unless>\n'
        "</robot>\n"
    )


def make_package(root: Path, links: int) -> Path:
    pkg = root / "bench_robot"
    (pkg / "urdf").mkdir(parents=True)
    (pkg / "package.xml").write_text(
        '<package format="2"><name>bench_robot</name><version>0.0.1</version><description>b</description>'
        '<maintainer email="b@example.com">b</maintainer><license>BSD</license></package>'
    )
    (pkg / "urdf" / "dims.yaml").write_text("radius: 0.03\nmass: 2.5\n")
    (pkg / "urdf" / "segment.xacro").write_text(MACROS)
    (pkg / "urdf" / "robot.urdf.xacro").write_text(description(links))
    return pkg / "urdf" / "robot.urdf.xacro"


def timed(command: list[str], env: dict[str, str], runs: int) -> tuple[float, str]:
    """Median wall time of ``runs`` whole commands, and the output of the last one."""
    times, out = [], ""
    for _ in range(runs):
        start = time.perf_counter()
        done = subprocess.run(command, env=env, capture_output=True, text=True, check=True)
        times.append(time.perf_counter() - start)
        out = done.stdout
    return statistics.median(times), out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=10)
    parser.add_argument("--links", type=int, default=LINKS)
    args = parser.parse_args()
    bindir = Path(sys.executable).parent
    with tempfile.TemporaryDirectory() as tmp:
        path = make_package(Path(tmp), args.links)
        env = dict(os.environ, ROS_PACKAGE_PATH=tmp)
        reference = [sys.executable, "-c", "import sys, xacro; sys.argv[0] = 'xacro'; sys.exit(xacro.main())"]
        ours = [str(bindir / "xacro")]
        ref_out = subprocess.run([*reference, str(path)], env=env, capture_output=True, text=True, check=True)
        our_out = subprocess.run([*ours, str(path)], env=env, capture_output=True, text=True, check=True)
        if ref_out.stdout != our_out.stdout:
            sys.exit("the two outputs differ; nothing timed")
        links = our_out.stdout.count("<link ")
        ref_time, _ = timed([*reference, str(path)], env, args.runs)
        our_time, _ = timed([*ours, str(path)], env, args.runs)
    print(f"xacro expansion, {links} links ({len(our_out.stdout)} bytes of URDF), median of {args.runs} runs")
    print(f"  reference xacro (upstream xacro.main): {ref_time * 1000:8.1f} ms")
    print(f"  ninjemys xacro:                        {our_time * 1000:8.1f} ms")
    print(f"  ratio ninjemys / reference:            {our_time / ref_time:8.2f}x")


if __name__ == "__main__":
    main()

"""catkin_make of a 10-package Python workspace: ninjemys vs Debian's real catkin_make (CMake).

Run: ``.venv/bin/python bench/catkin_make.py`` (``--rounds N``, default 3).

Each package is what the course texts make: ``catkin_create_pkg``'s files with rospy and std_msgs,
one message and one service, two scripts installed with ``catkin_install_python`` and a launch
file; package k depends on package k-1's messages. A round is a clean build (build/ and devel/
removed) of the same sources by each tool, timed as a whole process; the medians are compared.
"""

from __future__ import annotations

import argparse
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

PACKAGES = 10
DEBIAN = Path("/usr/bin/catkin_make")


def write_workspace(root: Path) -> None:
    for k in range(PACKAGES):
        name = f"bench_pkg{k}"
        pkg = root / "src" / name
        for sub in ("msg", "srv", "scripts", "launch"):
            (pkg / sub).mkdir(parents=True)
        dep = f"bench_pkg{k - 1}" if k else ""
        deps = f"<depend>{dep}</depend>" if dep else ""
        (pkg / "package.xml").write_text(
            f'<?xml version="1.0"?>\n<package format="2"><name>{name}</name><version>0.0.1</version>'
            '<description>bench</description><maintainer email="dev@example.com">dev</maintainer>'
            "<license>BSD</license><buildtool_depend>catkin</buildtool_depend><depend>rospy</depend>"
            f"<depend>std_msgs</depend>{deps}<build_depend>message_generation</build_depend>"
            "<exec_depend>message_runtime</exec_depend></package>\n"
        )
        (pkg / "msg" / f"Reading{k}.msg").write_text(
            "uint64 stamp_ns\nfloat32 value\nstring label\n"
            + (f"bench_pkg{k - 1}/Reading{k - 1} previous\n" if k else "")
        )
        (pkg / "srv" / f"Ask{k}.srv").write_text("int64 a\nint64 b\n---\nint64 sum\n")
        for script in ("talker.py", "listener.py"):
            (pkg / "scripts" / script).write_text("#!/usr/bin/env python3\nimport rospy\n")
            (pkg / "scripts" / script).chmod(0o755)
        (pkg / "launch" / f"{name}.launch").write_text(
            f'<launch><node pkg="{name}" type="talker.py" name="talker"/></launch>\n'
        )
        components = " ".join(["rospy", "std_msgs", "message_generation", *([dep] if dep else [])])
        (pkg / "CMakeLists.txt").write_text(
            f"cmake_minimum_required(VERSION 3.0.2)\nproject({name})\n"
            f"find_package(catkin REQUIRED COMPONENTS {components})\n"
            f"add_message_files(FILES Reading{k}.msg)\nadd_service_files(FILES Ask{k}.srv)\n"
            f"generate_messages(DEPENDENCIES std_msgs {dep})\n"
            f"catkin_package(CATKIN_DEPENDS rospy std_msgs message_runtime {dep})\n"
            "catkin_install_python(PROGRAMS scripts/talker.py scripts/listener.py\n"
            "  DESTINATION ${CATKIN_PACKAGE_BIN_DESTINATION})\n"
        )


def timed(command: list[str], cwd: Path, env: dict[str, str]) -> float:
    for space in ("build", "devel"):
        shutil.rmtree(cwd / space, ignore_errors=True)
    start = time.perf_counter()
    result = subprocess.run(command, cwd=cwd, env=env, capture_output=True, text=True)
    elapsed = time.perf_counter() - start
    if result.returncode != 0:
        raise SystemExit(f"{command[0]} failed:\n{result.stdout[-2000:]}\n{result.stderr[-2000:]}")
    return elapsed


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rounds", type=int, default=3)
    opts = parser.parse_args()
    root = Path(tempfile.mkdtemp(prefix="bench_catkin_"))
    ours_ws, debian_ws = root / "ours", root / "debian"
    for ws in (ours_ws, debian_ws):
        write_workspace(ws)
    ours_env = {k: v for k, v in os.environ.items() if k not in ("ROS_PACKAGE_PATH", "CMAKE_PREFIX_PATH")}
    debian_env = {"PATH": "/usr/bin:/bin", "HOME": str(root), "LANG": "C.UTF-8"}
    ours_cmd = [str(Path(sys.executable).parent / "catkin_make")]
    times: dict[str, list[float]] = {"ours": [], "debian": []}
    for _ in range(opts.rounds):
        times["ours"].append(timed(ours_cmd, ours_ws, ours_env))
        if DEBIAN.exists():
            times["debian"].append(timed([str(DEBIAN)], debian_ws, debian_env))
    shutil.rmtree(root, ignore_errors=True)
    print(f"catkin_make, {PACKAGES} Python packages, clean build (load {os.getloadavg()[0]:.1f}):")
    for name, values in times.items():
        if values:
            print(
                f"  {name:7s} median {statistics.median(values):6.2f} s  (min {min(values):.2f}, max {max(values):.2f})"
            )
    if times["debian"]:
        print(
            f"  ratio ours/debian: {statistics.median(times['ours']) / statistics.median(times['debian']):.3f}"
        )


if __name__ == "__main__":
    main()

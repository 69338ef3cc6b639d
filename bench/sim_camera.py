"""The simulator's camera alone, per frame: CPU time and instructions, by an older tree and by this one.

The URDF PuzzleBot's camera (colour + depth, 320x240) driving a circle in three worlds:

* ``office`` (our YAML world: walls and furniture),
* ``square`` (the course's 1 m square painted on the floor: the floor markings looked up per pixel),
* ``gazebo`` (a Gazebo ``.world`` written here the way Udacity's "Go Chase It" worlds are: the sun
  and ground plane included, a walled room, boxes, a cylinder and a white ball),

rendered in a child process by the tree at ``--before`` (default: main) and by this tree, alternating,
in one run. Two figures per frame:

* CPU: process CPU time per frame, the best of 5 repetitions of 300 frames (a shared machine's load
  disturbs it less than wall time);
* instructions: ``valgrind --tool=callgrind``'s instruction count of a run of 40 frames less that of
  the same run with no frame, over 40 (``--no-callgrind`` leaves it out: it takes a few minutes).

Run alone: ``.venv/bin/python bench/sim_camera.py [--before REV] [--rounds N] [--no-callgrind]``.
"""

from __future__ import annotations

import argparse
import os
import re
import shutil
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
URDF_MODEL = ROOT / "src/ninjemys/packages/share/puzzlebot_sim/robots/puzzlebot.urdf"

#: a Go-Chase-It-like world: the sun, the ground plane, a 6 x 6 m room, a white ball, boxes, a cylinder
GAZEBO_WORLD = """<?xml version="1.0"?>
<sdf version="1.6"><world name="default">
  <include><uri>model://sun</uri></include>
  <include><uri>model://ground_plane</uri></include>
  {models}
</world></sdf>
"""


def _model(name: str, pose: str, geometry: str, material: str) -> str:
    return (
        f'<model name="{name}"><static>true</static><pose>{pose}</pose><link name="link">'
        f'<collision name="c"><geometry>{geometry}</geometry></collision>'
        f'<visual name="v"><geometry>{geometry}</geometry><material><script>'
        "<uri>file://media/materials/scripts/gazebo.material</uri>"
        f"<name>{material}</name></script></material></visual></link></model>"
    )


def gazebo_world_text() -> str:
    """The benchmark's Gazebo world (also a fair picture of what the course worlds hold)."""
    walls = [
        ("wall_n", "0 3 0.5 0 0 0", "<box><size>6 0.15 1</size></box>", "Gazebo/Grey"),
        ("wall_s", "0 -3 0.5 0 0 0", "<box><size>6 0.15 1</size></box>", "Gazebo/Grey"),
        ("wall_e", "3 0 0.5 0 0 0", "<box><size>0.15 6 1</size></box>", "Gazebo/White"),
        ("wall_w", "-3 0 0.5 0 0 0", "<box><size>0.15 6 1</size></box>", "Gazebo/Grey"),
        ("ball", "1.5 0.5 0.1 0 0 0", "<sphere><radius>0.1</radius></sphere>", "Gazebo/White"),
        ("box_r", "-1.5 1.2 0.25 0 0 0.4", "<box><size>0.5 0.5 0.5</size></box>", "Gazebo/Red"),
        ("box_b", "0.5 -1.8 0.2 0 0 0", "<box><size>0.8 0.4 0.4</size></box>", "Gazebo/Blue"),
        (
            "can",
            "-1 -1 0.4 0 0 0",
            "<cylinder><radius>0.2</radius><length>0.8</length></cylinder>",
            "Gazebo/Green",
        ),
    ]
    return GAZEBO_WORLD.format(models="\n  ".join(_model(*w) for w in walls))


FRAMES = """
import math, sys, time
from ninjemys.sim.robot_model import load_robot_model
from ninjemys.sim.sdf import load_sdf_world
from ninjemys.sim.simcore import Simulation
from ninjemys.sim.world2d import load_world
from ninjemys.sim.worlds import world_path
urdf, world, frames, repeat = sys.argv[1], sys.argv[2], int(sys.argv[3]), int(sys.argv[4])
loaded = load_sdf_world(world) if world.endswith(".world") else load_world(world_path(world))
sim = Simulation(loaded, 0.01, 0)
r = sim.add_robot("pb", load_robot_model(urdf), 0.0, 0.0, 0.0)
poses = [(0.5 * math.cos(i * 0.05), 0.5 * math.sin(i * 0.05), i * 0.05) for i in range(max(frames, 1))]
for r.x, r.y, r.yaw in poses[:3]:
    sim.render(r)  # the first frames: OpenCV imported, scratch arrays touched
best = math.inf
for _ in range(repeat):
    t = time.process_time()
    for r.x, r.y, r.yaw in poses[:frames]:
        sim.render(r)
    best = min(best, (time.process_time() - t) / max(frames, 1))
print(best * 1e3)
"""


def frame_ms(src: Path | None, world: str) -> float:
    """CPU ms of one frame in ``world`` by the tree at ``src`` (None: this tree)."""
    out = subprocess.run(
        [sys.executable, "-c", FRAMES, str(URDF_MODEL), world, "300", "5"],
        env=_env(src),
        capture_output=True,
        text=True,
        check=True,
    )
    return float(out.stdout.strip().splitlines()[-1])


def _env(src: Path | None) -> dict[str, str]:
    env = dict(os.environ)
    if src is not None:
        env["PYTHONPATH"] = str(src)
    return env


def _instructions(src: Path | None, world: str, frames: int, tmp: Path) -> int:
    out_file = tmp / f"callgrind.{os.getpid()}.{frames}.out"
    subprocess.run(
        [
            "valgrind",
            "--tool=callgrind",
            f"--callgrind-out-file={out_file}",
            sys.executable,
            "-c",
            FRAMES,
            str(URDF_MODEL),
            world,
            str(frames),
            "1",
        ],
        env=_env(src),
        capture_output=True,
        text=True,
        check=True,
    )
    text = out_file.read_text(errors="replace")
    out_file.unlink()
    found = re.search(r"^summary:\s*(\d+)", text, re.MULTILINE) or re.search(
        r"^totals:\s*(\d+)", text, re.MULTILINE
    )
    if found is None:
        raise RuntimeError("callgrind wrote no summary")
    return int(found.group(1))


def frame_instructions(src: Path | None, world: str, tmp: Path, frames: int = 40) -> float:
    """Instructions of one frame: a run of ``frames`` frames less a run of none, over ``frames``."""
    return (_instructions(src, world, frames, tmp) - _instructions(src, world, 0, tmp)) / frames


def extract_tree(rev: str, dest: Path) -> Path:
    dest.mkdir(parents=True, exist_ok=True)
    archive = subprocess.run(["git", "-C", str(ROOT), "archive", rev, "src"], capture_output=True, check=True)
    subprocess.run(["tar", "-x", "-C", str(dest)], input=archive.stdout, check=True)
    return dest / "src"


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--before", default="main", help="the older tree's revision (default: main)")
    p.add_argument("--rounds", type=int, default=3, help="A/B rounds of the CPU figure")
    p.add_argument("--no-callgrind", action="store_true", help="leave out the instruction counts")
    p.add_argument("--worlds", default="office,square,gazebo", help="comma-separated")
    args = p.parse_args()
    rev = subprocess.run(
        ["git", "-C", str(ROOT), "rev-parse", "--short", args.before],
        capture_output=True,
        text=True,
        check=True,
    ).stdout.strip()
    with tempfile.TemporaryDirectory() as tmp_name:
        tmp = Path(tmp_name)
        old = extract_tree(args.before, tmp / "before")
        gz = tmp / "go_chase_it.world"
        gz.write_text(gazebo_world_text())
        worlds = {"office": "office", "square": "square", "gazebo": str(gz)}
        print(f"## the camera per frame, A/B: {rev} (before) and this tree (after), alternating")
        print("colour + depth, 320x240, the URDF PuzzleBot driving a circle; CPU: best of 5 x 300 frames,")
        print(f"median of {args.rounds} rounds; instructions: callgrind, 40 frames less none, per frame")
        print(
            "| world | CPU before | CPU after | after / before | instr. before | instr. after | after / before |"
        )
        print("|---|---:|---:|---:|---:|---:|---:|")
        for name in args.worlds.split(","):
            world = worlds[name]
            a: list[float] = []
            b: list[float] = []
            for _ in range(args.rounds):
                a.append(frame_ms(old, world))
                b.append(frame_ms(None, world))
            am, bm = statistics.median(a), statistics.median(b)
            ia = ib = float("nan")
            if not args.no_callgrind and shutil.which("valgrind"):
                ia = frame_instructions(old, world, tmp)
                ib = frame_instructions(None, world, tmp)
            print(
                f"| {name} | {am:.3f} ms | {bm:.3f} ms | {bm / am:.2f} | {ia / 1e6:.2f} M | {ib / 1e6:.2f} M "
                f"| {ib / ia:.2f} |"
            )
            print(f"load average: {' '.join(f'{v:.2f}' for v in os.getloadavg())}", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())

"""C++ message headers: ninjemys' generator vs Debian's gencpp on the same definitions.

Run: ``.venv/bin/python bench/gencpp_headers.py`` (``--rounds N``, default 3).

The packages are the ones only ninjemys provides plus visualization_msgs (control_msgs,
gazebo_msgs, fiducial_msgs, rosserial_msgs, smach_msgs, controller_manager_msgs,
visualization_msgs): every message, action message and service, as catkin_make writes them for a
C++ build. Ours: :func:`ninjemys.packages.cpp_msgs.write_prefix` into an empty directory (headers,
definitions, CMake configs), in this process. Debian's: gencpp's ``generate_from_file`` for each
definition in one ``/usr/bin/python3`` process (catkin starts one process per file, which is
slower still), headers only. A round times each once from scratch; the medians are compared.
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import statistics
import subprocess
import tempfile
import time
from pathlib import Path

from ninjemys.packages.cpp_msgs import write_prefix

PACKAGES = (
    "control_msgs",
    "gazebo_msgs",
    "fiducial_msgs",
    "rosserial_msgs",
    "smach_msgs",
    "controller_manager_msgs",
    "visualization_msgs",
)
TEMPLATES = Path("/usr/share/gencpp")
DRIVER = """\
import json, sys
import genmsg.template_tools as t
args = json.loads(sys.argv[1])
for pkg, path, out in args['files']:
    t.generate_from_file(path, pkg, out, '/usr/share/gencpp', [k + ':' + v for k, v in args['search'].items()],
                         {'msg.h.template': '@NAME@.h'}, {'srv.h.template': '@NAME@.h'})
"""


def ours(root: Path) -> tuple[float, int]:
    shutil.rmtree(root, ignore_errors=True)
    start = time.perf_counter()
    write_prefix(root, PACKAGES)
    elapsed = time.perf_counter() - start
    return elapsed, len(list((root / "include").rglob("*.h")))


def debian(prefix: Path, out: Path) -> tuple[float, int]:
    """gencpp on the definitions our prefix installs (the same texts), its dependencies included."""
    shutil.rmtree(out, ignore_errors=True)
    share = prefix / "share"
    search = {d.name: str(d / "msg") for d in share.iterdir()}
    files = [
        [package, str(path), str(out / package)]
        for package in PACKAGES
        for kind in ("msg", "srv")
        for path in sorted((share / package / kind).glob(f"*.{kind}"))
    ]
    start = time.perf_counter()
    subprocess.run(
        ["/usr/bin/python3", "-c", DRIVER, json.dumps({"search": search, "files": files})], check=True
    )
    elapsed = time.perf_counter() - start
    return elapsed, len(list(out.rglob("*.h")))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rounds", type=int, default=3)
    opts = parser.parse_args()
    root = Path(tempfile.mkdtemp(prefix="bench_gencpp_"))
    # the dependencies' definitions (std_msgs, geometry_msgs ...) for Debian's gencpp to resolve
    deps = root / "deps"
    write_prefix(
        deps, (*PACKAGES, "std_msgs", "geometry_msgs", "actionlib_msgs", "trajectory_msgs", "sensor_msgs")
    )
    times: dict[str, list[float]] = {"ours": [], "debian": []}
    counts: dict[str, int] = {}
    for _ in range(opts.rounds):
        elapsed, counts["ours"] = ours(root / "ours")
        times["ours"].append(elapsed)
        if TEMPLATES.is_dir():
            elapsed, counts["debian"] = debian(deps, root / "debian")
            times["debian"].append(elapsed)
    shutil.rmtree(root, ignore_errors=True)
    print(f"C++ headers for {len(PACKAGES)} message packages, from scratch (load {os.getloadavg()[0]:.1f}):")
    for name, values in times.items():
        if values:
            print(
                f"  {name:7s} {counts[name]:4d} headers  median {statistics.median(values):6.2f} s"
                f"  (min {min(values):.2f}, max {max(values):.2f})"
            )
    if times["debian"]:
        print(
            f"  ratio ours/debian: {statistics.median(times['ours']) / statistics.median(times['debian']):.3f}"
        )


if __name__ == "__main__":
    main()

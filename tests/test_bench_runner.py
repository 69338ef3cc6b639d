"""``make bench`` runs bench/run_all.py, which finds every benchmark (and none of the helpers)."""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def test_make_bench_calls_a_script_that_exists() -> None:
    makefile = (ROOT / "Makefile").read_text()
    recipe = re.search(r"^bench:.*\n((?:\t.*\n)+)", makefile, re.MULTILINE)
    assert recipe is not None
    scripts = re.findall(r"(bench/\S+\.py)", recipe.group(1))
    assert scripts and all((ROOT / s).is_file() for s in scripts)


def test_run_all_lists_the_benchmarks_not_the_helpers() -> None:
    out = subprocess.run(
        [sys.executable, str(ROOT / "bench" / "run_all.py"), "--list"],
        capture_output=True,
        text=True,
        check=True,
    ).stdout.split()
    assert {"node_rtt.py", "node_streams.py", "idl_serialization.py", "launch_startup.py"} <= set(out)
    assert not {
        "node_common.py",
        "node_roles.py",
        "node_roscpp.py",
        "master_common.py",
        "run_all.py",
        "ab.py",
    } & set(out)

"""A/B of any benchmark: the tree at a git revision (``--before``) and this tree, alternating, in one run
(a tool, not a benchmark: ``run_all.py`` does not list it, it has no ``main``).

Each side runs its own copy of the benchmark (``bench/`` and ``src/`` of that revision, extracted with
``git archive``; this tree's for the other side) under the venv's interpreter, with ``PYTHONPATH``
pointing at that side's ``src`` (the venv's editable install is a plain path entry, which
``PYTHONPATH`` precedes; the commands a benchmark starts inherit it). Rounds alternate
before/after so that a change in the machine's load falls on both sides alike; every round prints
the load average and the last ``--tail`` lines of each side's output, which carry the benchmark's
own figures. The machine is shared: compare the sides round by round, not with other runs.

Run: ``.venv/bin/python bench/ab.py --before ae3873e --rounds 2 bench/tf2_lookup.py --quick``.
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def extract(rev: str, dest: Path) -> Path:
    """``src/`` and ``bench/`` of ``rev`` under ``dest``; returns ``dest``."""
    archive = subprocess.run(
        ["git", "-C", str(ROOT), "archive", rev, "src", "bench"], capture_output=True, check=True
    )
    subprocess.run(["tar", "-x", "-C", str(dest)], input=archive.stdout, check=True)
    return dest


def run_side(tree: Path, script: str, args: list[str], timeout: float) -> tuple[str, float]:
    """(output, wall seconds) of ``script`` (a path relative to the tree) run from ``tree``."""
    env = dict(os.environ, PYTHONPATH=str(tree / "src"))
    start = time.monotonic()
    done = subprocess.run(
        [sys.executable, str(tree / script), *args],
        cwd=tree,
        env=env,
        capture_output=True,
        text=True,
        timeout=timeout,
        check=False,
    )
    out = done.stdout + (f"\n[exit {done.returncode}] {done.stderr[-2000:]}" if done.returncode else "")
    return out, time.monotonic() - start


def compare() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--before", required=True, help="the git revision to compare with")
    ap.add_argument("--rounds", type=int, default=2)
    ap.add_argument("--tail", type=int, default=30, help="lines of each side's output to print")
    ap.add_argument("--timeout", type=float, default=900.0)
    ap.add_argument("script", help="the benchmark, relative to the tree (bench/xxx.py)")
    ap.add_argument("args", nargs=argparse.REMAINDER, help="the benchmark's own arguments")
    opts = ap.parse_args()
    rev = subprocess.run(
        ["git", "-C", str(ROOT), "rev-parse", "--short", opts.before],
        capture_output=True,
        text=True,
        check=True,
    ).stdout.strip()
    with tempfile.TemporaryDirectory(prefix="ninjemys-ab-") as tmp:
        before = extract(opts.before, Path(tmp))
        sides = [(f"before {rev}", before), ("after (this tree)", ROOT)]
        for n in range(opts.rounds):
            for name, tree in sides if n % 2 == 0 else sides[::-1]:
                print(f"\n## round {n + 1}, {name}: {opts.script} {' '.join(opts.args)}")
                print(f"load average {os.getloadavg()[0]:.1f} (2 cores shared)", flush=True)
                out, took = run_side(tree, opts.script, opts.args, opts.timeout)
                print("\n".join(out.rstrip().splitlines()[-opts.tail :]))
                print(f"({took:.0f} s)", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(compare())

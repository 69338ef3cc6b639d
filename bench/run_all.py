"""Run every benchmark in bench/ in turn, then print a summary (``make bench``).

    .venv/bin/python bench/run_all.py [NAME ...] [--timeout SECONDS] [--list]

A benchmark is a bench/*.py with a top-level ``def main(`` (the shared helpers and the role scripts
the drivers start have none). Each runs alone with its default sizes, under this interpreter, its
output shown as it comes; one that fails or overruns is reported and the next one runs. NAME runs
only the benchmarks whose file name contains it (``node_``, ``bag_read``). The exit status is 1 if any
benchmark failed.
"""

from __future__ import annotations

import argparse
import os
import re
import subprocess
import sys
import time
from pathlib import Path

BENCH = Path(__file__).resolve().parent
_MAIN = re.compile(r"^def main\(", re.MULTILINE)


def benchmarks() -> list[Path]:
    """Every runnable benchmark, in name order (so related ones run next to each other)."""
    return [
        path
        for path in sorted(BENCH.glob("*.py"))
        if path.name != Path(__file__).name and _MAIN.search(path.read_text(encoding="utf-8"))
    ]


def run(path: Path, timeout: float) -> tuple[str, float]:
    """Run one benchmark with its output going straight to ours; its status and wall time."""
    print(f"\n=== {path.name} ===", flush=True)
    start = time.monotonic()
    proc = subprocess.Popen([sys.executable, str(path)], cwd=BENCH, start_new_session=True)
    try:
        code = proc.wait(timeout)
        status = "ok" if code == 0 else f"failed (exit {code})"
    except subprocess.TimeoutExpired:
        os.killpg(proc.pid, 9)  # its role processes and masters are in its session
        proc.wait()
        status = f"timed out after {timeout:.0f} s"
    except KeyboardInterrupt:
        os.killpg(proc.pid, 9)
        proc.wait()
        raise
    return status, time.monotonic() - start


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("names", nargs="*", help="run only benchmarks whose file name contains one of these")
    parser.add_argument("--timeout", type=float, default=1800.0, help="seconds allowed per benchmark")
    parser.add_argument("--list", action="store_true", help="list the benchmarks and exit")
    opts = parser.parse_args()
    chosen = [p for p in benchmarks() if not opts.names or any(n in p.name for n in opts.names)]
    if opts.list:
        print("\n".join(p.name for p in chosen))
        return
    if not chosen:
        sys.exit(f"no benchmark matches {' '.join(opts.names)} (see --list)")
    print(f"{len(chosen)} benchmarks; machine: {os.cpu_count()} CPUs, load {os.getloadavg()[0]:.1f}")
    results = [(path.name, *run(path, opts.timeout)) for path in chosen]
    print("\n=== summary ===")
    width = max(len(name) for name, _, _ in results)
    for name, status, seconds in results:
        print(f"{name:{width}s}  {seconds:7.1f} s  {status}")
    failed = [name for name, status, _ in results if status != "ok"]
    print(
        f"{len(results) - len(failed)} of {len(results)} ran to the end"
        + (f"; failed: {', '.join(failed)}" if failed else "")
    )
    sys.exit(1 if failed else 0)


if __name__ == "__main__":
    main()

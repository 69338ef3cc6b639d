"""roscore start-to-ready and stop-on-Ctrl-C, ninjemys vs Debian's ROS 1, in one run.

    .venv/bin/python bench/master_startup.py [--runs 5]

Measures, per implementation (median of --runs launches): launch -> first successful getSystemState,
launch -> /rosout node up (subscribes /rosout, publishes /rosout_agg), and SIGINT -> process exit.
"""

from __future__ import annotations

import argparse

from master_common import OURS, REAL, median, ratio, require_ros1, start_core, wait_ready, wait_rosout


def measure(impl: str, runs: int) -> dict[str, float]:
    ready, rosout, stop = [], [], []
    for _ in range(runs):
        core = start_core(impl)
        try:
            ready.append(wait_ready(core))
            rosout.append(wait_rosout(core))
            stop.append(core.stop())
        finally:
            core.kill()
    return {"ready": median(ready), "rosout": median(rosout), "stop": median(stop)}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=5)
    args = parser.parse_args()
    require_ros1()
    results = {impl: measure(impl, args.runs) for impl in (REAL, OURS)}
    print(f"roscore start/stop, median of {args.runs} runs (seconds)")
    print(f"{'figure':<34}{REAL:>10}{OURS:>10}   ratio")
    labels = {
        "ready": "launch -> getSystemState answers",
        "rosout": "launch -> /rosout up",
        "stop": "Ctrl-C -> exited",
    }
    for key, label in labels.items():
        real, ours = results[REAL][key], results[OURS][key]
        print(f"{label:<34}{real:>10.3f}{ours:>10.3f}   {ratio(ours, real)}")


if __name__ == "__main__":
    main()

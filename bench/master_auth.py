"""The master with authentication on (NINJEMYS_SECRET) vs off: registration and lookup throughput.

    .venv/bin/python bench/master_auth.py [--calls 3000] [--rounds 3]

Two of our masters run at once, one with a secret; one client in this process registers publishers
(registerPublisher, a new topic each) and looks nodes up (lookupNode), signing its requests only for
the secured master. Rounds alternate between the two so load on the machine hits both alike. Target:
authentication costs at most 10 % of the throughput.
"""

from __future__ import annotations

import argparse
import os
import statistics
import time
from collections.abc import Iterator
from contextlib import contextmanager

from master_common import OURS, start_core, wait_ready
from ninjemys.master.client import MasterClient

SECRET = "bench-secret-0123456789abcdef"


@contextmanager
def secret(on: bool) -> Iterator[None]:
    old = os.environ.pop("NINJEMYS_SECRET", None)
    if on:
        os.environ["NINJEMYS_SECRET"] = SECRET
    try:
        yield
    finally:
        os.environ.pop("NINJEMYS_SECRET", None)
        if old is not None:
            os.environ["NINJEMYS_SECRET"] = old


def rates(uri: str, calls: int, tag: str) -> tuple[float, float]:
    client = MasterClient(uri, f"/bench_{tag}", timeout=30)
    start = time.perf_counter()
    for i in range(calls):
        client.register_publisher(f"/{tag}/topic_{i}", "std_msgs/String", "http://127.0.0.1:1/")
    register = calls / (time.perf_counter() - start)
    start = time.perf_counter()
    for _ in range(calls):
        client.lookup_node(f"/bench_{tag}")
    lookup = calls / (time.perf_counter() - start)
    client.close()
    return register, lookup


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--calls", type=int, default=3000)
    parser.add_argument("--rounds", type=int, default=3)
    opts = parser.parse_args()
    with secret(True):
        secured = start_core(OURS)
    with secret(False):
        plain = start_core(OURS)
    try:
        for core, on in ((secured, True), (plain, False)):
            with secret(on):
                wait_ready(core)
        results: dict[bool, list[tuple[float, float]]] = {True: [], False: []}
        for r in range(opts.rounds):
            for on, core in ((False, plain), (True, secured)) if r % 2 else ((True, secured), (False, plain)):
                with secret(on):
                    results[on].append(rates(core.uri, opts.calls, f"r{r}{int(on)}"))
    finally:
        secured.kill()
        plain.kill()
    print(f"master XML-RPC, {opts.calls} calls x {opts.rounds} rounds (load {os.getloadavg()[0]:.1f})")
    for label, k in (("registerPublisher", 0), ("lookupNode", 1)):
        off = statistics.median(x[k] for x in results[False])
        on = statistics.median(x[k] for x in results[True])
        print(
            f"  {label:18s} off {off:8.0f}/s   on {on:8.0f}/s   on/off {on / off:.2f}  (cost {100 * (1 - on / off):+.1f} %)"
        )


if __name__ == "__main__":
    main()

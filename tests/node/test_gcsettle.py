"""Issue 25, tail latency: the first node's start-up freezes the objects alive then (gc.freeze), once
per process, so no later collection traverses them (the first generation-1 collection after start-up
was a 1-2 ms pause in some round trip); NINJEMYS_GC_FREEZE=0 leaves the collector alone."""

from __future__ import annotations

import json
import os
import subprocess
import sys

import pytest

_PROBE = """
import gc, json, sys
from ninjemys.node import Node
before = gc.get_freeze_count()
a = Node("gc_a", anonymous=True, master_uri=sys.argv[1], rosout=False, logger_services=False)
first = gc.get_freeze_count()
junk = [[i] for i in range(1000)]
b = Node("gc_b", anonymous=True, master_uri=sys.argv[1], rosout=False, logger_services=False)
second = gc.get_freeze_count()
a.shutdown("over"); b.shutdown("over")
print(json.dumps({"before": before, "first": first, "second": second}))
"""


def _probe(uri: str, **env: str) -> dict[str, int]:
    out = subprocess.run(
        [sys.executable, "-c", _PROBE, uri],
        env={**os.environ, **env},
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert out.returncode == 0, out.stderr[-2000:]
    return json.loads(out.stdout.strip().splitlines()[-1])


@pytest.mark.parametrize("setting", ["1", "0"])
def test_the_first_node_freezes_start_up_once(master, setting: str) -> None:  # noqa: ANN001
    counts = _probe(master.uri, NINJEMYS_GC_FREEZE=setting)
    assert counts["before"] == 0
    if setting == "0":
        assert counts["first"] == counts["second"] == 0
        return
    # thousands of start-up objects; the second node froze nothing more (the junk list stays young)
    assert counts["first"] > 5000
    assert counts["second"] <= counts["first"]

"""A subscriber's worker thread asks for a shorter scheduler slice (ninjemys.node.slices), and only it."""

from __future__ import annotations

import subprocess
import sys
import threading
from pathlib import Path

import pytest

from ninjemys.node import slices
from ninjemys.testing import wait_until

SRC = str(Path(__file__).resolve().parents[2] / "src")


def _own_slice() -> int | None:
    """The calling thread's EEVDF slice in ns as the kernel reports it, None where it does not."""
    try:
        text = Path("/proc/thread-self/sched").read_text()
    except OSError:
        return None
    for line in text.splitlines():
        if line.startswith("se.slice"):
            return int(line.split(":")[1])
    return None


def _in_thread(fn):
    out: list = []
    t = threading.Thread(target=lambda: out.append(fn()))
    t.start()
    t.join()
    return out[0]


def test_shorten_takes_a_quarter_of_this_thread_only() -> None:
    before = _in_thread(_own_slice)
    if before is None or not sys.platform.startswith("linux"):
        pytest.skip("no EEVDF slice to read on this kernel")
    done, after, spawned = _in_thread(lambda: (slices.shorten(), _own_slice(), _in_thread(_own_slice)))
    if not done:
        pytest.skip("this kernel does not take a custom slice (older than 6.12)")
    assert after == max(100_000, before // 4)
    assert spawned == before  # a thread the worker starts (a callback's) gets the default again
    assert _own_slice() == before  # the calling (main) thread keeps its own


def test_turned_off_by_the_environment() -> None:
    code = (
        "import threading; from ninjemys.node import slices; out = []\n"
        "t = threading.Thread(target=lambda: out.append(slices.shorten())); t.start(); t.join()\n"
        "print(out[0])\n"
    )
    env = {"PYTHONPATH": SRC, "NINJEMYS_WORKER_SLICE": "0", "PATH": "/usr/bin:/bin"}
    got = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, check=True)
    assert got.stdout.strip() == "False"


def test_a_worker_thread_gets_it(make_node) -> None:
    """A live subscriber's worker runs with the shorter slice; the thread that made it keeps its own."""
    default = _in_thread(_own_slice)
    if default is None or not _in_thread(slices.shorten):
        pytest.skip("this kernel reports or takes no custom slice (older than 6.12)")
    from node_msgs import String

    node = make_node("slice_sub")
    sub = node.subscriber("/slice_topic", String, lambda m: None)
    sched = Path(f"/proc/self/task/{sub._thread.native_id}/sched")

    def worker_slice() -> int:
        text = sched.read_text()
        return int(next(x for x in text.splitlines() if x.startswith("se.slice")).split(":")[1])

    wait_until(lambda: worker_slice() != default, what="the worker's slice to change")
    assert worker_slice() == max(100_000, default // 4)
    assert _own_slice() == default

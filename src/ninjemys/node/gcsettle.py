"""Start-up's objects out of the cyclic garbage collector's way (issue 25: tail latency).

A node's start-up leaves some 10^5 objects (modules, classes, functions, generated message code, the
node's own structures) in the collector's young generations, and the first collection of generation 1
after it traverses them all: measured 1.1-1.7 ms in the middle of a round trip of bench/node_rtt.py's
ping, once per run, where the collections of the steady state take 30-80 us. ``gc.freeze()`` moves
them to the permanent generation, which no collection traverses: that same collection took 0.13 ms.

Once per process, at the end of the first :class:`~ninjemys.node.Node`'s start-up: what is alive then
is the process's long-lived state. A later freeze would also pin the garbage cycles made since (a
shut-down node's, in a test run), which the collector could then never free. The costs, accepted:
frozen objects are not listed by ``gc.get_objects()`` (debugging tools see only later ones), and
garbage cycles already made by then (start-up makes next to none) stay. ``NINJEMYS_GC_FREEZE=0``
leaves the collector alone.
"""

from __future__ import annotations

import gc
import os

_settled = False


def settle() -> None:
    """Freeze the objects alive now, the first time a node has started in this process."""
    global _settled
    if _settled:
        return
    _settled = True
    if os.environ.get("NINJEMYS_GC_FREEZE", "1") != "0":
        gc.freeze()

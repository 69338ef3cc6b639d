"""A shorter scheduler slice for the threads that wake user threads (Linux 6.12+, EEVDF).

Why: a subscriber's worker thread calls back, and the callback typically wakes another thread of
the process (``threading.Event.set``: a ping's main thread waits for its pong). On one CPU the woken
thread pre-empts the worker at once (a futex wake is no "sync" wake-up), finds the GIL still held,
sleeps on it, and the worker is pre-empted twice more as it lets the GIL go (CPython signals the
GIL's condition, then unlocks its mutex, each a wake-up): six context switches per message where
one would do. EEVDF picks the runnable thread with the earliest virtual deadline, a thread's slice
sets how far ahead its deadline lies, and since Linux 6.12 a thread may ask for its own slice
(``sched_setattr``'s ``sched_runtime``, no privilege needed): a worker whose slice is a quarter of
the default more often keeps the CPU over a freshly woken thread of the default slice until it
sleeps in its next ``recv`` (dropping the GIL with nobody waiting for it), and the woken thread then
finds the GIL free. Measured in a ping-pong on one CPU (load 20): the bare Python shape
(``bench/floor_rtt.py``'s thread+event) 5.4 → 3.0 context switches and 30 → 24 µs of CPU per round
trip; two nodes (``bench/node_rtt.py``'s roles) 6.2 → 4.6 context switches per round trip, both
processes counted.

The cost: a worker that runs a long callback while the CPU is contended is switched out every
quarter slice instead of every slice (the same share of the CPU, in shorter turns). Python offers no
``sched_setattr``, so ``ctypes`` calls it (imported by the worker on its first start, ~2 ms).
Threads and processes a callback starts do not inherit it (``SCHED_FLAG_RESET_ON_FORK``). Elsewhere
(another OS, an unknown architecture, an older kernel that ignores the field, a thread not of the
normal policy) nothing changes. ``NINJEMYS_WORKER_SLICE=0`` turns it off.
"""

from __future__ import annotations

import os
import struct
import sys

TYPE_CHECKING = False  # importing typing costs start-up time; checkers set it
if TYPE_CHECKING:
    from typing import Any

#: ``sched_setattr`` / ``sched_getattr`` by machine (the generic table's numbers for the newer ports)
_SYSCALLS = {
    "x86_64": (314, 315),
    "amd64": (314, 315),
    "aarch64": (274, 275),
    "arm64": (274, 275),
    "riscv64": (274, 275),
}
#: struct sched_attr up to sched_period (SCHED_ATTR_SIZE_VER0, 48 bytes): size, policy, flags, nice,
#: priority, runtime, deadline, period
_ATTR = struct.Struct("=IIQiIQQQ")
_SCHED_OTHER = 0
#: the flag set with the slice: threads and processes a callback starts get the default slice back
#: (and, as the kernel does it, nice 0 for a negative nice), not the worker's
_RESET_ON_FORK = 0x01
#: the kernel's smallest custom slice (ns); a shorter request is raised to it anyway
_MIN_SLICE = 100_000
#: the worker's slice is this fraction of the thread's own (the default: 0.75 ms times 1 + log2 of the
#: CPUs, at most 3 ms); a half was enough in the measurements, a quarter leaves a margin
_FRACTION = 4

_disabled = False
_syscall: Any = None


def shorten() -> bool:
    """Give the calling thread a quarter of its scheduler slice (see the module docstring); True
    when the kernel took it. Never raises: a failure turns the attempt off for the process."""
    global _disabled, _syscall
    if _disabled:
        return False
    numbers = _SYSCALLS.get(os.uname().machine.lower()) if sys.platform.startswith("linux") else None
    if numbers is None or os.environ.get("NINJEMYS_WORKER_SLICE", "1") == "0":
        _disabled = True
        return False
    try:
        import ctypes

        if _syscall is None:
            _syscall = ctypes.CDLL(None, use_errno=True).syscall
        syscall = _syscall
        buf = ctypes.create_string_buffer(_ATTR.size)
        if syscall(numbers[1], 0, buf, _ATTR.size, 0) != 0:
            raise OSError(ctypes.get_errno(), "sched_getattr")
        _, policy, _, nice, priority, slice_ns, _, _ = _ATTR.unpack(buf.raw)
        if policy != _SCHED_OTHER or not slice_ns:
            return False  # a real-time or batch thread (or a kernel that reports no slice): as it is
        wanted = max(_MIN_SLICE, slice_ns // _FRACTION)
        if wanted >= slice_ns:
            return False
        attr = ctypes.create_string_buffer(
            _ATTR.pack(_ATTR.size, policy, _RESET_ON_FORK, nice, priority, wanted, 0, 0), _ATTR.size
        )
        if syscall(numbers[0], 0, attr, 0) != 0:
            raise OSError(ctypes.get_errno(), "sched_setattr")
    except (OSError, AttributeError, ImportError, ValueError, struct.error):
        _disabled = True
        return False
    return True

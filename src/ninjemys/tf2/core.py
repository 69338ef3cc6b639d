"""The tf2 buffer core: frames, their time caches, and lookups between them. No ROS inside.

ROS 1's ``tf2::BufferCore`` (geometry2 ``buffer_core.cpp``, ``cache.cpp``, ``static_cache.cpp``) is
the reference for every rule here: each child frame keeps a time-sorted cache of transforms to its
parent (``cache_time`` of history, 10 s by default; static frames keep one entry for all time),
lookups interpolate (lerp + slerp) between the two entries around the requested time and never
extrapolate, time 0 means "the latest time every link of the chain has", and a lookup composes the
chain from the source up to the common ancestor and down to the target. The error texts are tf2's.

Where we differ, on purpose:
- A repeated stamp replaces the stored entry (the newest data wins) and logs at most one debug line
  per frame; ROS 1 drops it with a TF_REPEATED_DATA warning per message (geometry2#467).
- Bad input (empty ids, a frame its own parent, NaN, a non-unit quaternion, a transform that would
  close a loop) is dropped with one line naming the frames and the authority; tf2 accepts loops and
  only fails later lookups.
- Lookups are memoized per frame: each frame remembers its transform to the top of its tree for the
  last time it was asked about, valid until the next insertion, so a lookup is usually one
  ``inverse(a) * b`` instead of a walk. When that path cannot answer (a frame above the common
  ancestor has no data for that time), the exact tf2 walk runs and gives tf2's answer or error.
  A lookup at a time not asked about before composes each side only up to the lowest common
  ancestor, in one loop, interpolating each link from a per-segment record made on first use
  (slerp as ``A cos(rθ) + C sin(rθ)``, see :meth:`Frame._segment`). Links that rotate about z only
  are composed as complex numbers, and a side whose planar links share a segment is evaluated from a
  per-side composite (:meth:`BufferCore._side_composite`); both equal the general path to rounding.
- ``can_transform`` with a timeout waits on a condition that insertions signal (no polling sleeps).
- Raw TFMessages (``add_raw``, what the listener uses) are queued and decoded in batches on the next
  query, runs of one layout with numpy (:mod:`ninjemys.tf2.bulk`).

Times are integer nanoseconds and transforms 7-tuples here; :mod:`ninjemys.tf2.buffer` puts the
message-level API (TransformStamped, ``ninjemys.rostime`` values, timeouts) on top.

The class is assembled from one module per concern: :mod:`~ninjemys.tf2.storage` (frames, their caches,
the shared state), :mod:`~ninjemys.tf2.ingest` (insertion and the raw queue),
:mod:`~ninjemys.tf2.reference` (tf2's walk, the answer of record), :mod:`~ninjemys.tf2.fastpath` (the
memos and composites above) and :mod:`~ninjemys.tf2.introspect` (the text views). ``BufferCore(fast=False)``
(or :data:`FAST` set to False before construction) answers every lookup and check with the reference walk
alone: the differential tests run both and compare.
"""

from __future__ import annotations

import time as _wall
from collections.abc import Callable
from typing import Any

from ninjemys.interrupt import wait_slice
from ninjemys.tf2 import math as tfm
from ninjemys.tf2.errors import LookupException, TransformException
from ninjemys.tf2.fastpath import FastLookup
from ninjemys.tf2.ingest import BULK_MIN, OWED_BATCHES, PENDING_MAX, QUATERNION_TOLERANCE, REPEAT_REPORT_AFTER
from ninjemys.tf2.introspect import Introspection
from ninjemys.tf2.storage import (
    DEFAULT_CACHE_TIME,
    MAX_GRAPH_DEPTH,
    NO_ERROR,
    NO_PARENT,
    Frame,
    Reporter,
    _raise,
)

# the lookup path new buffers take when not told: True for the fast path, False for tf2's walk alone
# (the differential tests flip it to compare both)
FAST = True


class BufferCore(Introspection, FastLookup):
    """tf2's BufferCore: set transforms in, look transforms up. Thread-safe (one lock, one condition)."""

    def __init__(
        self, cache_time: float = DEFAULT_CACHE_TIME, report: Reporter | None = None, fast: bool | None = None
    ) -> None:
        """``cache_time`` is seconds of history per frame; ``report`` receives the one line about bad input
        (default: this module's logger at error level); ``fast=False`` answers with tf2's walk alone
        (default: :data:`FAST`)."""
        super().__init__(cache_time, report, FAST if fast is None else fast)

    def add_change_listener(self, fn: Callable[[], None]) -> None:
        """Call ``fn()`` after new data arrived (on the inserting thread, outside the buffer's lock): what a
        filter that holds messages until their transform is available waits on (tf2's transformable
        callbacks). ``fn`` may query the buffer; it should be quick."""
        self._listeners.append(fn)
        self._tell_sources()

    def add_source(self, source: Any) -> None:
        """Register a feeder that delivers lazily (the listener of a lazy ``/tf`` subscription):
        ``source.pull()`` is called before every query, outside the buffer's lock, to deliver what
        has arrived, so a lookup sees every message the kernel already holds; ``source.set_eager(b)``
        is told whether anybody waits for new data (a ``wait_for_transform`` waiter or a change
        listener), which then must arrive without being asked for."""
        self._sources.append(source)
        source.set_eager(bool(self._waiters or self._listeners))

    def remove_source(self, source: Any) -> None:
        if source in self._sources:
            self._sources.remove(source)

    def lookup(self, target_frame: str, source_frame: str, t: int) -> tuple[int, tuple]:
        """``(stamp_ns, 7 floats)``: the transform that maps data in ``source_frame`` into ``target_frame``
        at time ``t`` (0 = latest common). Raises tf2's exceptions with tf2's texts."""
        if self._sources:
            self._pull()
        with self._lock:
            if self._pending or self._owing:
                self._drain_for(target_frame, source_frame)
            frames = self._frames
            target = frames.get(target_frame)
            source = frames.get(source_frame)
            if target is None or source is None or target is source:
                if target_frame == source_frame:
                    if t == 0:
                        t = target.latest if target is not None and target.has_cache else 0
                    return t, tfm.IDENTITY
                target = self._validate("lookupTransform argument target_frame", target_frame)
                source = self._validate("lookupTransform argument source_frame", source_frame)
            if not self.fast:
                return self._walk_time(target, source, t)
            return self._lookup(target, source, t)

    def lookup_full(
        self, target_frame: str, target_t: int, source_frame: str, source_t: int, fixed_frame: str
    ) -> tuple[int, tuple]:
        """The advanced lookup: ``source`` at ``source_t`` into ``fixed``, then ``fixed`` at ``target_t``
        into ``target``. Returns ``(stamp of the second lookup, 7 floats)``."""
        self._pull()
        with self._lock:
            self._drain_for(target_frame, source_frame, fixed_frame)
            self._validate("lookupTransform argument target_frame", target_frame)
            self._validate("lookupTransform argument source_frame", source_frame)
            self._validate("lookupTransform argument fixed_frame", fixed_frame)
            _, first = self.lookup(fixed_frame, source_frame, source_t)
            stamp, second = self.lookup(target_frame, fixed_frame, target_t)
            return stamp, tfm.matrix_signed(tfm.compose(second, first))

    def can_transform(self, target_frame: str, source_frame: str, t: int) -> tuple[bool, str]:
        """tf2's ``canTransform`` with its error text: (possible, why not)."""
        if target_frame == source_frame:
            return True, ""
        self._pull()
        with self._lock:
            if self._pending or self._owing:
                self._drain_for(target_frame, source_frame)
            target = self._frames.get(target_frame)
            source = self._frames.get(source_frame)
            if target is None or source is None:
                if self._warn_frame_id("canTransform argument target_frame", target_frame) or (
                    self._warn_frame_id("canTransform argument source_frame", source_frame)
                ):
                    return False, ""
                parts = []
                if target is None:
                    parts.append(f"canTransform: target_frame {target_frame} does not exist.")
                if source is None:
                    parts.append(f"canTransform: source_frame {source_frame} does not exist.")
                return False, " ".join(parts)
            return self._can(target, source, t)

    def _can(self, target: Frame, source: Frame, t: int) -> tuple[bool, str]:
        if target is source:
            return True, ""
        if not self.fast:
            err: list[str] = []
            code, _, _ = self._walk(target, source, t, err, accumulate=False)
            return code == NO_ERROR, "".join(err)
        try:  # the lookup's caches answer most checks without a walk
            self._lookup(target, source, t)
            return True, ""
        except TransformException:
            pass  # the walk says why, in tf2's words
        why: list[str] = []
        code, _, _ = self._walk(target, source, t, why, accumulate=False)
        return code == NO_ERROR, "".join(why)

    def can_transform_full(
        self, target_frame: str, target_t: int, source_frame: str, source_t: int, fixed_frame: str
    ) -> tuple[bool, str]:
        """tf2's advanced ``canTransform``: target<-fixed at target_t and fixed<-source at source_t."""
        for what, name in (
            ("canTransform argument target_frame", target_frame),
            ("canTransform argument source_frame", source_frame),
            ("canTransform argument fixed_frame", fixed_frame),
        ):
            if self._warn_frame_id(what, name):
                return False, ""
        self._pull()
        with self._lock:
            self._drain_for(target_frame, source_frame, fixed_frame)
            target = self._frames.get(target_frame)
            source = self._frames.get(source_frame)
            fixed = self._frames.get(fixed_frame)
            if target is None or source is None or fixed is None:
                parts = []
                if target is None:
                    parts.append(f"canTransform: target_frame {target_frame} does not exist.")
                if source is None:
                    parts.append(f"canTransform: source_frame {source_frame} does not exist.")
                if fixed is None:
                    parts.append(f"fixed_frame: {fixed_frame}does not exist.")
                return False, " ".join(parts)
            ok, why = self._can(target, fixed, target_t)
            if not ok:
                return ok, why
            return self._can(fixed, source, source_t)

    def wait_for_transform(
        self,
        check: Callable[[], tuple[bool, str]],
        timeout: float,
        now: Callable[[], float] | None = None,
        cancelled: Callable[[], bool] | None = None,
    ) -> tuple[bool, str]:
        """Run ``check`` now and after every insertion until it is True or ``timeout`` seconds pass.

        ``now`` is the clock the timeout is measured on (the node's ROS time; wall time by default);
        the waiting itself sleeps on the buffer's condition, so data wakes it at once. A jump back of
        more than 3 s in ``now`` (a bag loop) ends the wait, as tf2_ros does.
        """
        clock = now or _wall.monotonic
        start = clock()
        deadline = start + timeout
        ok, why = check()
        if ok or timeout <= 0.0:
            return ok, why
        changed = self._changed
        with changed:
            self._waiters += 1
        if self._waiters == 1 and self._sources:
            self._tell_sources()  # data must now arrive by itself, as it comes
        try:
            while True:
                seen = self._seq  # read before the check: an insertion after it bumps it
                ok, why = check()
                current = clock()
                if ok or current >= deadline or current + 3.0 < start or (cancelled and cancelled()):
                    return ok, why
                with changed:
                    if self._seq == seen:
                        changed.wait(
                            wait_slice(min(deadline - current, 1.0) if cancelled else deadline - current)
                        )
        finally:
            with changed:
                self._waiters -= 1
            if not self._waiters and self._sources:
                self._tell_sources()

    def latest_common_time(self, target_frame: str, source_frame: str) -> int:
        """tf2_py's ``get_latest_common_time`` (raises LookupException / TransformException)."""
        self._pull()
        with self._lock:
            self._drain()
            target = self._validate("get_latest_common_time", target_frame)
            source = self._validate("get_latest_common_time", source_frame)
            err: list[str] = []
            code, t = self._common_time(target, source, err)
            if code != NO_ERROR:
                raise TransformException("".join(err))
            return t

    def chain(
        self, target_frame: str, target_t: int, source_frame: str, source_t: int, fixed_frame: str
    ) -> list[str]:
        """tf2's ``_chainAsVector``: the frame names from source to target through ``fixed_frame``."""
        self._pull()
        with self._lock:
            self._drain()
            source = self._frames.get(source_frame)
            fixed = self._frames.get(fixed_frame)
            target = self._frames.get(target_frame)
            if source is None or fixed is None or target is None:
                missing = next(
                    n
                    for n, f in ((source_frame, source), (fixed_frame, fixed), (target_frame, target))
                    if f is None
                )
                raise LookupException(f'"{missing}" passed to chain does not exist. ')
            err: list[str] = []
            code, _, first = self._walk(fixed, source, source_t, err, accumulate=False)
            if code != NO_ERROR:
                _raise(code, err)
            code, _, second = self._walk(target, fixed, target_t, err, accumulate=False)
            if code != NO_ERROR:
                _raise(code, err)
            if first and second and first[-1] is second[0]:
                first = first[:-1]
            return [f.name for f in (*first, *second)]


__all__ = [
    "BULK_MIN",
    "DEFAULT_CACHE_TIME",
    "FAST",
    "MAX_GRAPH_DEPTH",
    "NO_PARENT",
    "OWED_BATCHES",
    "PENDING_MAX",
    "QUATERNION_TOLERANCE",
    "REPEAT_REPORT_AFTER",
    "BufferCore",
    "Frame",
    "Reporter",
]

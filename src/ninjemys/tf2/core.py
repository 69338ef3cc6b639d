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
"""

from __future__ import annotations

import logging
import threading
import time as _wall
from bisect import bisect_left, bisect_right
from cmath import rect
from collections import deque
from collections.abc import Callable, Iterable, Sequence
from itertools import repeat
from math import acos, atan2, cos, isfinite, sin, sqrt
from operator import attrgetter, itemgetter, lt
from typing import Any

from ninjemys.errors import DeserializationError
from ninjemys.interrupt import wait_slice
from ninjemys.tf2 import math as tfm
from ninjemys.tf2.bulk import Layout, valid
from ninjemys.tf2.errors import (
    ConnectivityException,
    ExtrapolationException,
    InvalidArgumentException,
    LookupException,
    TimeoutException,
    TransformException,
)
from ninjemys.tf2.wire import decode_tf_message

_log = logging.getLogger(__name__)

DEFAULT_CACHE_TIME = 10.0
MAX_GRAPH_DEPTH = 1000
QUATERNION_TOLERANCE = 10e-6  # tf2: |x²+y²+z²+w² - 1| must stay under this
NO_PARENT = "NO_PARENT"
REPEAT_REPORT_AFTER = 10.0  # seconds before the same bad-input line is reported again
PENDING_MAX = 50  # raw messages queued before the listener's thread decodes them itself
OWED_BATCHES = 4096  # batches a layout may owe its frames (they expire after cache_time)
_SEEN = (-1,)  # a segment looked up once: its composite is made on the second lookup (no history is -1)
BULK_MIN = 2  # a run this long of one layout is decoded with numpy; a single message per transform

# tf2_msgs/TF2Error codes, as walk results
NO_ERROR = 0
LOOKUP_ERROR = 1
CONNECTIVITY_ERROR = 2
EXTRAPOLATION_ERROR = 3

Entry = tuple  # (parent: Frame, (tx, ty, tz, qx, qy, qz, qw))
# C-level getters for the bulk appends (map over the frames of a layout)
_BULK = attrgetter("bulk")
_STAMPS = attrgetter("stamps")
_DATA = attrgetter("data")
_SEGS = attrgetter("segs")
_LAST = itemgetter(-1)


def _ascending(prev: list[int], rows: list[list[int]]) -> bool:
    """Every column strictly increases from ``prev`` through ``rows`` (C-level loops over columns)."""
    for row in rows:
        if not all(map(lt, prev, row)):
            return False
        prev = row
    return True


def _consume(iterator: Iterable[Any]) -> None:
    """Run a ``map`` for its effects."""
    deque(iterator, 0)


Reporter = Callable[[str], None]


def _secs(ns: int) -> float:
    """Seconds as ROS's ``toSec`` computes them (secs + 1e-9 * nsecs), for tf2's texts."""
    s, n = divmod(ns, 1_000_000_000)
    return s + 1e-9 * n


class Frame:
    """One frame: its cache of transforms to its parent (empty for a frame that is only ever a parent)."""

    __slots__ = (
        "name",
        "number",
        "keep",
        "static",
        "has_cache",
        "stamps",
        "data",
        "segs",
        "latest",
        "parent",
        "authority",
        "memo_gen",
        "memo_t",
        "memo_val",
        "quiet_repeat",
        "warned_old",
        "path_topology",
        "path",
        "index",
        "pmin_gen",
        "pmin",
        "point_of",
        "point",
        "sides",
        "bulk",
        "bulk_j",
        "applied",
    )

    def __init__(self, name: str, number: int, keep: int = 0) -> None:
        self.name = name
        self.number = number
        # history tf2 keeps (ns): an entry older than the newest minus this is pruned there, so it
        # is invisible here too, although the list is trimmed in steps (see BufferCore._prune_slack)
        self.keep = keep or 1 << 62
        self.static = False
        self.has_cache = False  # tf2: frames_[id] is null until the frame is somebody's child
        self.stamps: list[int] = []  # ascending
        self.data: list[Entry] = []
        # segs[i]: the interpolation record of the segment from entry i - 1 to entry i, made on first
        # use (see _segment); None until then, and again whenever either end changes
        self.segs: list[tuple | None] = []
        self.latest = 0  # newest stamp (0 for static frames, as tf2's StaticCache says)
        self.parent: Frame | None = None  # parent of the newest entry
        self.authority = ""
        self.memo_gen = -1
        self.memo_t = -1
        self.memo_val: tuple | None = None
        self.quiet_repeat = False
        self.warned_old = 0.0
        self.path_topology = -1
        self.path: list[Frame] = []  # this frame, its newest parent, ... up to the top of its tree
        self.index: dict[Frame, int] = {}
        self.pmin_gen = -1
        self.pmin: list[int] = []  # pmin[k]: the oldest non-zero newest stamp among path[:k]
        self.point_of: Entry | None = None  # the entry ``point`` was made from (the newest one)
        self.point: tuple = ()
        # by ancestor: [composites by segment start (None: off), lead frame, links (frame, parent) up to
        # it]; the lead is the first dynamic link, whose stamps locate the segment around a time
        self.sides: dict[Frame, list] = {}
        # the Layout whose batches alone wrote this frame's history since its last check (None after
        # any other insertion): its batches then append without per-frame checks, and may be owed
        # (kept in the layout until a query needs this frame, see BufferCore._settle_frame)
        self.bulk: Layout | None = None
        self.bulk_j = 0  # this frame's transform in that layout
        self.applied = 0  # how many of the layout's batches (counted from its first) are in our lists

    def __repr__(self) -> str:
        return f"Frame({self.name!r})"

    # -- tf2's TimeCache -------------------------------------------------------------------------
    def _resolve(self, i: int) -> Entry:
        """Entry ``i`` as ``(parent, 7 floats)``. Entries inserted in bulk are ``(parent, values, (row,
        column))`` (a place in the numpy array of their batch) until first read: most history is never
        looked at."""
        e = self.data[i]
        if len(e) == 3:
            e = self.data[i] = (e[0], tuple(e[1][e[2]].tolist()))
        return e

    def at(self, t: int, err: list[str] | None) -> Entry | None:
        """The entry for time ``t`` (0 = newest), interpolated; None (and a tf2 text in ``err``) if none."""
        data = self.data
        if not data:
            return None
        if t == 0 or self.static:
            e = data[-1]
            return e if len(e) == 2 else self._resolve(-1)
        stamps = self.stamps
        if stamps[-1] == t:  # the newest entry (a latest-time lookup)
            e = data[-1]
            return e if len(e) == 2 else self._resolve(-1)
        n = len(stamps)
        i = bisect_left(stamps, t)
        lo = 0  # the oldest entry tf2 would still hold (it prunes on every insertion)
        if stamps[0] + self.keep < self.latest:
            lo = bisect_left(stamps, self.latest - self.keep)
        if lo < i < n:
            if stamps[i] == t:
                return self._resolve(i)
            return self._interpolate(i, t)
        if i == lo and stamps[i] == t:
            return self._resolve(i)
        if err is not None:
            if n - lo == 1:
                # tf2 formats this one into a 116-byte buffer: with two ten-digit times it loses its
                # tail ("... is in the buffe"), and programs see exactly that
                err.append(
                    (
                        "Lookup would require extrapolation at time %.09f, but only time %.09f is in the buffer"
                        % (_secs(t), _secs(stamps[lo]))
                    )[:115]
                )
            elif i == n:
                latest = stamps[-1]
                err.append(
                    "Lookup would require extrapolation %.09fs into the future.  Requested time %.09f but the "
                    "latest data is at time %.09f" % (_secs(t - latest), _secs(t), _secs(latest))
                )
            else:
                earliest = stamps[lo]
                err.append(
                    "Lookup would require extrapolation %.09fs into the past.  Requested time %.09f but the "
                    "earliest data is at time %.09f" % (_secs(earliest - t), _secs(t), _secs(earliest))
                )
        return None

    def _interpolate(self, i: int, t: int) -> Entry:
        """Between entries ``i - 1`` and ``i``: lerp for the translation, slerp (the shorter arc) for the
        rotation, as tf2's ``TimeCache::interpolate``; across a change of parent, the older entry."""
        rec = self.segs[i] or self._segment(i)
        r = (t - rec[2]) * rec[3]
        if rec[0]:
            _, p, _, _, e, z, de, dz, c, th = rec
            if r:
                e += r * de
                z += r * dz
                if th:
                    c *= rect(1.0, r * th)
            return p, (e.real, e.imag, z, 0.0, 0.0, c.imag, c.real)
        _, p, _, _, x, y, z, dx, dy, dz, qx, qy, qz, qw, cx, cy, cz, cw, th = rec
        if r:
            x += r * dx
            y += r * dy
            z += r * dz
            if th:
                a = r * th
                co = cos(a)
                si = sin(a)
                qx, qy, qz, qw = qx * co + cx * si, qy * co + cy * si, qz * co + cz * si, qw * co + cw * si
            else:
                qx, qy, qz, qw = _nlerp(qx, qy, qz, qw, cx, cy, cz, cw, r)
        return p, (x, y, z, qx, qy, qz, qw)

    def _point(self) -> tuple:
        """The newest entry as a record (see :meth:`_segment`) that interpolates to itself: what a lookup
        at the newest stamp, or through a static frame, composes. Remade when the newest entry changes."""
        e = self.data[-1]
        if e is self.point_of:
            return self.point
        if len(e) == 3:
            e = self._resolve(-1)
        self.point_of = e
        p, (x, y, z, qx, qy, qz, qw) = e
        if qx == 0.0 and qy == 0.0:
            rec: tuple = (True, p, 0, 0.0, complex(x, y), z, 0j, 0.0, complex(qw, qz), 0.0)
        else:
            rec = (False, p, 0, 0.0, x, y, z, 0.0, 0.0, 0.0, qx, qy, qz, qw, 0.0, 0.0, 0.0, 0.0, 0.0)
        self.point = rec
        return rec

    def _segment(self, i: int) -> tuple:
        """The record that makes interpolating between entries ``i - 1`` and ``i`` a few multiplies:
        ``(planar, parent, t0, 1/(t1 - t0), ...)``, then for a general segment the translation at t0 and
        its change to t1, quaternion A at t0, C and theta; for a planar one (both rotations about z
        only, as most mobile-robot links are) the translation's x + iy at t0 and its change as complex
        numbers, z and its change, A's w + iz as a complex number and the signed angle theta.

        Slerp from A to B (B negated if that is the shorter arc) by ratio r is
        ``(A sin((1-r)θ) + B sin(rθ)) / sin θ`` (tf2's form); with ``C = (B - A cos θ) / sin θ``, the unit
        quaternion orthogonal to A in their plane, it is ``A cos(rθ) + C sin(rθ)``: the same rotation
        (to rounding) for two trigonometric calls. When A and B are nearly equal (θ under 1e-3, where
        sin θ vanishes) the record holds ``C = B - A`` and θ = 0: a normalized lerp, exact to rounding
        there. For rotations about z alone, quaternions ``w + z k`` multiply as complex numbers
        ``w + z i``, and C is A times i: the slerp is ``A e^{irθ}`` (one complex multiply by
        ``cmath.rect(1, rθ)``, exact at any θ). Across a change of parent tf2 returns the older entry: a
        record with no change."""
        older = self.data[i - 1]
        if len(older) == 3:
            older = self._resolve(i - 1)
        newer = self.data[i]
        if len(newer) == 3:
            newer = self._resolve(i)
        stamps = self.stamps
        t0 = stamps[i - 1]
        x, y, z, ax, ay, az, aw = older[1]
        b = newer[1]
        bx, by, bz, bw = b[3], b[4], b[5], b[6]
        rec: tuple
        if ax == 0.0 and ay == 0.0 and (bx == 0.0 and by == 0.0 or older[0] is not newer[0]):
            qa = complex(aw, az)
            if older[0] is not newer[0]:
                rec = (True, older[0], t0, 0.0, complex(x, y), z, 0j, 0.0, qa, 0.0)
            else:
                qb = complex(bw, bz)
                d = qa.conjugate() * qb  # A⁻¹B = e^{iθ}
                if d.real < 0.0:  # q and -q are one rotation: take the short way round
                    d = -d
                rec = (True, older[0], t0, 1.0 / (stamps[i] - t0), complex(x, y), z)
                rec += (complex(b[0] - x, b[1] - y), b[2] - z, qa, atan2(d.imag, d.real))
        elif older[0] is not newer[0]:
            rec = (False, older[0], t0, 0.0, x, y, z, 0.0, 0.0, 0.0, ax, ay, az, aw, 0.0, 0.0, 0.0, 0.0, 1.0)
        else:
            dot = ax * bx + ay * by + az * bz + aw * bw
            if dot < 0.0:  # q and -q are one rotation: take the short way round
                bx, by, bz, bw, dot = -bx, -by, -bz, -bw, -dot
            if dot > 0.9999995:
                th = 0.0
                cx, cy, cz, cw = bx - ax, by - ay, bz - az, bw - aw
            else:
                th = acos(dot)
                k = 1.0 / sin(th)
                cx, cy, cz, cw = (
                    (bx - ax * dot) * k,
                    (by - ay * dot) * k,
                    (bz - az * dot) * k,
                    (bw - aw * dot) * k,
                )
            rec = (False, older[0], t0, 1.0 / (stamps[i] - t0), x, y, z, b[0] - x, b[1] - y, b[2] - z)
            rec += (ax, ay, az, aw, cx, cy, cz, cw, th)
        self.segs[i] = rec
        return rec

    def parent_at(self, t: int, err: list[str] | None) -> Frame | None:
        """tf2's ``getParent``: the parent for time ``t`` (the older entry's), without interpolating."""
        if not self.data:
            return None
        if self.static or t == 0:
            return self.data[-1][0]
        e = self.at(t, err)
        return None if e is None else e[0]

    def latest_time_and_parent(self) -> tuple[int, Frame | None]:
        if not self.data:
            return 0, None
        return self.latest, self.data[-1][0]

    def oldest(self) -> int:
        """The oldest stamp tf2 would hold (0 for static frames)."""
        if self.static or not self.stamps:
            return 0
        stamps = self.stamps
        if stamps[0] + self.keep < self.latest:
            return stamps[bisect_left(stamps, self.latest - self.keep)]
        return stamps[0]


class BufferCore:
    """tf2's BufferCore: set transforms in, look transforms up. Thread-safe (one lock, one condition)."""

    def __init__(self, cache_time: float = DEFAULT_CACHE_TIME, report: Reporter | None = None) -> None:
        """``cache_time`` is seconds of history per frame; ``report`` receives the one line about bad input
        (default: this module's logger at error level)."""
        self.cache_time_ns = int(round(cache_time * 1e9))
        # history is trimmed back to cache_time once it is this much longer (trimming on every insertion
        # shifts the whole list each time): a frame keeps between cache_time and 1/16 more
        self._prune_slack = self.cache_time_ns >> 4
        self._report: Reporter = report or _log.error
        self._frames: dict[str, Frame] = {}
        self._order: list[Frame] = []  # by frame number (tf2's frameIDs_reverse, minus NO_PARENT)
        self._lock = threading.RLock()
        # waiters for new data sleep on their own condition, not the buffer's lock: a waiter's check
        # pulls from the sources outside that lock (see add_source), and the notifier never blocks
        self._changed = threading.Condition(threading.Lock())
        self._waiters = 0
        self._seq = 0  # bumped (while anybody waits) by every insertion: what waiters wait for
        self._sources: list[Any] = []
        self._gen = 0  # bumped by every accepted insertion: memos of older generations are stale
        self._last_t = -1  # the time of the previous non-latest lookup (a repeat fills the memos)
        self._asked_gen = -1  # the generation of the previous latest-time lookup (a repeat caches minima)
        self._topology = 0  # bumped when a frame appears or a newest parent changes
        self._history = 0  # bumped when stored history changes other than at its new end (composites)
        self._floor = 0  # the newest oldest-kept stamp after any pruning: older composites are stale
        self._pending: list[tuple[bytes, str, bool]] = []  # raw TFMessages not decoded yet
        self._listeners: list[Callable[[], None]] = []
        self._layouts: dict[tuple[str, int], Layout] = {}
        self._owing: set[Layout] = set()  # layouts holding batches not yet in all their frames' lists
        # some frame's history holds more than one parent: a lookup may then reach frames off the
        # newest-parent paths, so queries settle every owed batch (until clear)
        self._mixed = False
        self._reported: dict[str, float] = {}

    @property
    def cache_time(self) -> float:
        return self.cache_time_ns / 1e9

    # -- frames ----------------------------------------------------------------------------------
    def _frame_or_new(self, name: str) -> Frame:
        f = self._frames.get(name)
        if f is None:
            f = Frame(name, len(self._order) + 1, self.cache_time_ns)
            self._frames[name] = f
            self._order.append(f)
            self._topology += 1
        return f

    def frame_exists(self, name: str) -> bool:
        """tf2's ``_frameExists``: the name is known (as a child or as a parent)."""
        self._pull()
        with self._lock:
            self._drain()
            return name in self._frames

    def child_frames(self) -> list[str]:
        """The frames that have a parent now (the keys of :meth:`all_frames_as_yaml`), in tf2's order."""
        self._pull()
        with self._lock:
            self._drain()
            return [f.name for f in self._order if f.has_cache and f.data]

    def frame_names(self) -> list[str]:
        """Every known frame, in the order tf2 numbered them (``_getFrameStrings``)."""
        self._pull()
        with self._lock:
            self._drain()
            return [f.name for f in self._order]

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

    def _pull(self) -> None:
        for source in self._sources:
            source.pull()

    def _tell_sources(self) -> None:
        eager = bool(self._waiters or self._listeners)
        for source in self._sources:
            source.set_eager(eager)

    def _notify(self) -> None:
        """Wake the ``wait_for_transform`` waiters (new data may answer them)."""
        with self._changed:
            self._seq += 1
            self._changed.notify_all()

    def _changed_data(self) -> None:
        for fn in self._listeners:
            fn()

    # -- insertion -------------------------------------------------------------------------------
    def set_transforms(
        self,
        items: Iterable[Sequence],
        authority: str = "default_authority",
        is_static: bool = False,
    ) -> int:
        """Insert many ``(parent, child, stamp_ns, tx, ty, tz, qx, qy, qz, qw)`` under one lock; returns
        how many were accepted. Each refused one gets one reported line; the rest still go in."""
        accepted = 0
        problems: list[str] = []
        with self._lock:
            self._drain()
            for item in items:
                why = self._insert(item, authority, is_static)
                if why is None:
                    accepted += 1
                elif why:
                    problems.append(why)
            if accepted:
                self._gen += 1
        if accepted and self._waiters:
            self._notify()
        if problems:
            self._report_once(problems)
        if accepted and self._listeners:
            self._changed_data()
        return accepted

    def add_raw(self, data: bytes, authority: str = "default_authority", is_static: bool = False) -> None:
        """Queue a serialized TFMessage; it is decoded and inserted with the others that arrived
        before the next query (or once ``PENDING_MAX`` are waiting), many at a time: consecutive
        messages of one layout cost a few numpy operations together instead of Python work per
        transform (a listener's CPU is mostly spent decoding, geometry2#513)."""
        self.add_raw_many((data,), authority, is_static)

    def add_raw_many(
        self, data: Sequence[bytes], authority: str = "default_authority", is_static: bool = False
    ) -> None:
        """:meth:`add_raw` for several messages of one publisher, in order."""
        with self._lock:
            self._pending.extend(zip(data, repeat(authority), repeat(is_static)))
            if len(self._pending) >= PENDING_MAX:
                self._decode_pending()
        if self._waiters:
            self._notify()
        if self._listeners:
            self._changed_data()

    def _drain(self) -> None:
        """Decode and insert every queued message, in arrival order, and settle every owed batch (lock
        held): what a query that may read any frame needs."""
        if self._pending:
            self._decode_pending()
        if self._owing:
            self._settle_all()

    def _drain_for(self, *names: str) -> None:
        """As :meth:`_drain`, but settle owed batches only in the frames a lookup or check between
        ``names`` can read: each named frame and its newest parents up to the top of its tree. Owed
        batches never change a frame's parent, so while no history holds two parents for a frame
        (``_mixed``) a lookup reads no other frame (lock held)."""
        if self._pending:
            self._decode_pending()
        if not self._owing:
            return
        if self._mixed:
            self._settle_all()
            return
        frames = self._frames
        for name in names:
            f = frames.get(name)
            if f is None:
                continue
            path = self._path(f)
            if path is None:  # a loop (cannot be stored, but tf2's answer then needs every frame)
                self._settle_all()
                return
            for g in path:
                layout = g.bulk
                if layout is not None and g.applied < layout.owed_end:
                    self._settle_frame(g)

    def _decode_pending(self) -> None:
        pending = self._pending
        self._pending = []
        problems: list[str] = []
        accepted = 0
        i = 0
        n = len(pending)
        while i < n:
            data, who, static = pending[i]
            size = len(data)
            j = i + 1
            while j < n and pending[j][1] == who and pending[j][2] == static and len(pending[j][0]) == size:
                j += 1
            run = [p[0] for p in pending[i:j]]
            got = self._read_run(run, who) if j - i >= BULK_MIN and not static else None
            if got is not None:
                accepted += self._insert_columns(got[0], got[1], who, problems)
            else:
                for d in run:
                    try:
                        items = decode_tf_message(d)
                    except DeserializationError as exc:
                        problems.append(
                            f"{'/tf_static' if static else '/tf'}: dropped a message from {who}: {exc}"
                        )
                        continue
                    for item in items:
                        why = self._insert(item, who, static)
                        if why is None:
                            accepted += 1
                        elif why:
                            problems.append(why)
            i = j
        if accepted:
            self._gen += 1
        if problems:
            self._report_once(problems)

    def _read_run(self, run: list[bytes], who: str) -> tuple[Layout, tuple] | None:
        """Stamps and numbers of a run of same-size messages from one publisher, if they share a layout
        and all their values are good; None sends the run through the per-transform path."""
        key = (who, len(run[0]))
        layout = self._layouts.get(key)
        if layout is None or not layout.matches(run[0]):
            try:
                layout = Layout(run[0])
            except DeserializationError:
                return None
            if len(self._layouts) > 1000:
                self._layouts.clear()
            self._layouts[key] = layout
        got = layout.read(run)
        if got is None or not valid(got[1], QUATERNION_TOLERANCE):
            return None
        return layout, got

    def _insert_columns(self, layout: Layout, got: tuple, who: str, problems: list[str]) -> int:
        """Append each transform's ``k`` new entries to its frame (lock held). An entry stays
        ``(parent, values, (row, column))`` of the batch's array until first read: most history is
        never looked at.

        When every frame of the layout was last written by this layout's batches and the new stamps
        continue each frame's history in order (one vectorized check), the batch is not appended
        now: the layout keeps it, owed to its frames, and a query appends it to the frames it reads
        (:meth:`_drain_for`, :meth:`_settle_frame`). A listener asked 20 times a second for one chain
        then touches the few frames of that chain, not all 50; batches older than ``cache_time`` that
        no query needed expire unread. Otherwise each column is checked on its own, and a column
        that does not continue its frame's history (new frame or parent, old or repeated stamps)
        goes through :meth:`_insert` entry by entry."""
        stamps, values = got
        k = stamps.shape[0]
        rows = stamps.tolist()
        in_order = _ascending(rows[0], rows[1:])
        children = layout.children_frames
        if (
            in_order
            and children is not None
            and layout.last_row is not None
            and list(map(_BULK, children)).count(layout) == len(children)
            and _ascending(layout.last_row, rows[:1])
        ):
            last = rows[-1]
            layout.owe(list(zip(*rows, strict=True)), values, k, max(last))
            layout.last_row = last
            # a frame nobody asks about never needs batches older than cache_time: they expire
            # unread (a frame that missed some is cut back to cache_time when it is settled)
            layout.expire(min(last) - self.cache_time_ns)
            self._owing.add(layout)
            if len(layout.owed) >= OWED_BATCHES:  # stamps that hardly advance: bound the memory
                self._settle_layout(layout)
            return k * len(children)
        columns = list(zip(*rows, strict=True))
        frames = self._frames
        keep = self.cache_time_ns
        slack = keep + self._prune_slack
        pairs = layout.frames
        if pairs is None:
            pairs = [
                (frames.get(p), frames.get(c)) for p, c in zip(layout.parents, layout.children, strict=True)
            ]
            if all(p is not None and c is not None for p, c in pairs):
                layout.frames = pairs
                layout.children_frames = [c for _, c in pairs]
        cells = layout.cells(k)
        nones = [None] * k
        count = 0
        whole = True  # every column went in as a column: the layout owns all its frames now
        for j, (parent, child) in enumerate(pairs):
            col = columns[j]
            if child is not None and child.bulk is not None and child.applied < child.bulk.owed_end:
                self._settle_frame(child)
            if (
                child is None
                or parent is None
                or child.static
                or child.parent is not parent
                or col[0] <= child.latest
                or not child.stamps
                or not (in_order or all(a < b for a, b in zip(col, col[1:], strict=False)))
            ):
                whole = False
                for stamp, v in zip(col, values[:, j, :].tolist(), strict=True):
                    why = self._insert((layout.parents[j], layout.children[j], stamp, *v), who, False)
                    if why is None:
                        count += 1
                    elif why:
                        problems.append(why)
                continue
            child.authority = who
            if child.bulk is not layout:
                child.bulk = layout
                child.bulk_j = j
                child.applied = layout.owed_end
            st = child.stamps
            st.extend(col)
            child.data.extend(zip(repeat(parent, k), repeat(values, k), cells[j], strict=True))
            child.segs.extend(nones)
            latest = col[-1]
            child.latest = latest
            if st[0] < latest - slack:
                cut = bisect_left(st, latest - keep)
                del st[:cut]
                del child.data[:cut]
                del child.segs[:cut]
                if st[0] > self._floor:
                    self._floor = st[0]
            count += k
        layout.last_row = rows[-1] if whole and in_order else None
        return count

    def _settle_frame(self, f: Frame) -> None:
        """Append to ``f``'s lists the batches its layout owes it (lock held)."""
        layout = f.bulk
        assert layout is not None
        j = f.bulk_j
        parent = layout.frames[j][0]  # type: ignore[index]
        st, data, segs = f.stamps, f.data, f.segs
        missed = f.applied < layout.owed_base  # batches expired before this frame took them
        for columns, values, k, _newest in layout.owed[max(0, f.applied - layout.owed_base) :]:
            st.extend(columns[j])
            data.extend(zip(repeat(parent, k), repeat(values, k), layout.cells(k)[j], strict=True))
            segs.extend(repeat(None, k))
        f.applied = layout.owed_end
        f.latest = latest = st[-1]
        if missed or st[0] < latest - self.cache_time_ns - self._prune_slack:
            self._prune((f,), missed)

    def _settle_layout(self, layout: Layout) -> None:
        """Append every owed batch of ``layout`` to all its frames and forget the batches (lock held).
        The frames no lookup settled meanwhile (usually all but a few) take each batch in C-level
        ``map`` loops over the frames: a Python loop per frame costs more than the numbers when a
        batch holds only a few messages."""
        children = layout.children_frames or []
        end = layout.owed_end
        base = layout.owed_base
        behind = [f for f in children if f.bulk is layout and f.applied <= base]
        if behind and layout.owed:
            missed = any(f.applied < base for f in behind)
            pick = itemgetter(*[f.bulk_j for f in behind])
            one = len(behind) == 1
            cols: Any = ()
            for columns, values, k, _newest in layout.owed:
                flat, slices, nones = layout.entries(k)
                entries = list(zip(flat[0], repeat(values, len(flat[1])), flat[1], strict=True))
                cols = [pick(columns)] if one else pick(columns)
                _consume(map(list.extend, map(_STAMPS, behind), cols))
                spans = [pick(slices)] if one else pick(slices)
                _consume(map(list.extend, map(_DATA, behind), map(entries.__getitem__, spans)))
                _consume(map(list.extend, map(_SEGS, behind), repeat(nones, len(behind))))
            _consume(map(setattr, behind, repeat("latest"), map(_LAST, cols)))
            _consume(map(setattr, behind, repeat("applied"), repeat(end, len(behind))))
            self._prune(behind, missed)
        for f in children:
            if f.bulk is layout and f.applied < end:
                self._settle_frame(f)
        layout.forget_owed()
        self._owing.discard(layout)

    def _settle_all(self) -> None:
        for layout in list(self._owing):
            self._settle_layout(layout)

    def _prune(self, frames: Iterable[Frame], exact: bool = False) -> None:
        """Trim each frame's history back to ``cache_time`` once it is ``_prune_slack`` longer; with
        ``exact`` (a frame whose expired batches it never took) to ``cache_time`` itself, so that no
        lookup interpolates across the batches it lacks: they all lie before that."""
        keep = self.cache_time_ns
        slack = keep if exact else keep + self._prune_slack
        for f in frames:
            st = f.stamps
            latest = f.latest
            if st and st[0] < latest - slack:
                cut = bisect_left(st, latest - keep)
                del st[:cut]
                del f.data[:cut]
                del f.segs[:cut]
                if st[0] > self._floor:
                    self._floor = st[0]

    def _report_once(self, lines: list[str]) -> None:
        """Report each line, but the same line at most once per ``REPEAT_REPORT_AFTER`` seconds: a broadcaster
        that sends the same bad transform at 100 Hz gets one line, not a hundred a second."""
        now = _wall.monotonic()
        with self._lock:
            fresh = [line for line in lines if now - self._reported.get(line, -1e9) >= REPEAT_REPORT_AFTER]
            for line in fresh:
                self._reported[line] = now
            if len(self._reported) > 10_000:
                self._reported.clear()
        for line in fresh:
            self._report(line)

    def _insert(self, item: Sequence, authority: str, is_static: bool) -> str | None:
        """Insert one item (lock held). None when stored, else the line to report ('' = stay quiet)."""
        parent_name, child_name, stamp, tx, ty, tz, qx, qy, qz, qw = item
        if parent_name.startswith("/"):
            parent_name = parent_name[1:]
        if child_name.startswith("/"):
            child_name = child_name[1:]
        if child_name == parent_name:
            return (
                f'TF_SELF_TRANSFORM: Ignoring transform from authority "{authority}" with frame_id and '
                f'child_frame_id "{child_name}" because they are the same'
            )
        if not child_name:
            return (
                f'TF_NO_CHILD_FRAME_ID: Ignoring transform from authority "{authority}" (frame_id "{parent_name}") '
                "because child_frame_id not set"
            )
        if not parent_name:
            return (
                f'TF_NO_FRAME_ID: Ignoring transform with child_frame_id "{child_name}" from authority '
                f'"{authority}" because frame_id not set'
            )
        if not (
            isfinite(tx)
            and isfinite(ty)
            and isfinite(tz)
            and isfinite(qx)
            and isfinite(qy)
            and isfinite(qz)
            and isfinite(qw)
        ):
            return (
                f'TF_NAN_INPUT: Ignoring transform for child_frame_id "{child_name}" (parent "{parent_name}") '
                f'from authority "{authority}" because of a nan value in the transform '
                f"({tx:f} {ty:f} {tz:f}) ({qx:f} {qy:f} {qz:f} {qw:f})"
            )
        if abs(qx * qx + qy * qy + qz * qz + qw * qw - 1.0) >= QUATERNION_TOLERANCE:
            return (
                f'TF_DENORMALIZED_QUATERNION: Ignoring transform for child_frame_id "{child_name}" '
                f'(parent "{parent_name}") from authority "{authority}" because of an invalid quaternion '
                f"in the transform ({qx:f} {qy:f} {qz:f} {qw:f})"
            )
        frames = self._frames
        child = frames.get(child_name) or self._frame_or_new(child_name)
        parent = frames.get(parent_name) or self._frame_or_new(parent_name)
        if child.bulk is not None and child.applied < child.bulk.owed_end:
            self._settle_frame(child)  # its history in order before it changes
        if parent.has_cache and parent.parent is not None and child.parent is not parent:
            loop = self._path_to(parent, child)
            if loop is not None:
                return (
                    f'TF_LOOP: Ignoring transform for child_frame_id "{child_name}" with frame_id '
                    f'"{parent_name}" from authority "{authority}" because it would close a loop: '
                    + " -> ".join(f.name for f in loop)
                    + f" -> {child_name}"
                )
        entry = (parent, (tx, ty, tz, qx, qy, qz, qw))
        if child.stamps and parent is not child.parent and not child.static:
            self._mixed = True  # this history will hold two parents
        if not child.has_cache:
            child.has_cache = True
            child.static = is_static
        child.authority = authority
        child.bulk = None
        if child.static:
            if not child.data or child.data[-1][0] is not parent:
                self._topology += 1
            child.data = [entry]
            child.stamps = [stamp]
            child.segs = [None]
            child.parent = parent
            self._history += 1
            return None
        stamps = child.stamps
        if not stamps or stamp > stamps[-1]:
            if child.parent is not parent:
                self._topology += 1
                child.parent = parent
            stamps.append(stamp)
            child.data.append(entry)
            child.segs.append(None)
            child.latest = stamp
            if stamps[0] < stamp - self.cache_time_ns - self._prune_slack:
                i = bisect_left(stamps, stamp - self.cache_time_ns)
                del stamps[:i]
                del child.data[:i]
                del child.segs[:i]
                if stamps[0] > self._floor:
                    self._floor = stamps[0]
            return None
        if stamps[-1] > stamp + self.cache_time_ns:
            now = _wall.monotonic()
            if now - child.warned_old >= 5.0:
                child.warned_old = now
                _log.warning(
                    f"TF_OLD_DATA ignoring data from the past for frame {child_name} (parent {parent_name}) at "
                    f"time {_secs(stamp):f} according to authority {authority} (its newest data is "
                    f"{_secs(stamps[-1] - stamp):.3f} s later; this line repeats at most every 5 s per frame)"
                )
            return ""
        i = bisect_left(stamps, stamp)
        if stamps[i] == stamp:  # a repeated stamp: the newest data wins, quietly (geometry2#467)
            if child.data[i][0] is not entry[0] and i == len(stamps) - 1:
                self._topology += 1
                child.parent = parent
            child.data[i] = entry
            self._history += 1
            segs = child.segs
            segs[i] = None  # both segments that end on this entry change
            if i + 1 < len(segs):
                segs[i + 1] = None
            if not child.quiet_repeat:
                child.quiet_repeat = True
                _log.debug(
                    "TF_REPEATED_DATA for frame %s (parent %s) at time %f from %s: the stored entry was "
                    "replaced (said once per frame)",
                    child_name,
                    parent_name,
                    _secs(stamp),
                    authority,
                )
            return None
        stamps.insert(i, stamp)
        child.data.insert(i, entry)
        child.segs.insert(i, None)
        child.segs[i + 1] = None  # the segment the new entry splits
        self._history += 1
        return None

    def _path_to(self, start: Frame, goal: Frame) -> list[Frame] | None:
        """``[goal, ..., start]`` when ``goal`` is an ancestor of ``start`` through newest parents, else None."""
        chain = [start]
        f = start.parent
        while f is not None and len(chain) <= MAX_GRAPH_DEPTH:
            chain.append(f)
            if f is goal:
                chain.reverse()
                return chain
            f = f.parent if f.data else None
        return None

    def clear(self) -> None:
        """Forget all non-static data (tf2 keeps static transforms across ``clear``)."""
        self._pull()  # what arrived before the clear goes too
        with self._lock:
            self._pending = [p for p in self._pending if p[2]]  # unread static data still counts
            for layout in self._owing:
                layout.forget_owed()
            self._owing.clear()
            for layout in self._layouts.values():
                layout.last_row = None
            self._mixed = False
            self._drain()
            for f in self._order:
                if f.has_cache and not f.static:
                    f.stamps = []
                    f.data = []
                    f.segs = []
                    f.latest = 0
                    f.parent = None
                    f.bulk = None
            self._gen += 1
            self._topology += 1

    # -- names -----------------------------------------------------------------------------------
    def _validate(self, what: str, name: str) -> Frame:
        """tf2's ``validateFrameId``: InvalidArgument for '' or '/x', LookupException when unknown."""
        f = self._frames.get(name)
        if f is not None:
            return f
        if not name:
            raise InvalidArgumentException(
                f"Invalid argument passed to {what} in tf2 frame_ids cannot be empty"
            )
        if name.startswith("/"):
            raise InvalidArgumentException(
                f"Invalid argument \"{name}\" passed to {what} in tf2 frame_ids cannot start with a '/' like: "
            )
        raise LookupException(f'"{name}" passed to {what} does not exist. ')

    def _warn_frame_id(self, what: str, name: str) -> bool:
        """tf2's ``warnFrameId`` (used by canTransform): True (and a debug line) for a malformed id."""
        if not name:
            _log.debug("Invalid argument passed to %s in tf2 frame_ids cannot be empty", what)
            return True
        if name.startswith("/"):
            _log.debug(
                "Invalid argument \"%s\" passed to %s in tf2 frame_ids cannot start with a '/'", name, what
            )
            return True
        return False

    # -- latest common time ----------------------------------------------------------------------
    def _path(self, f: Frame) -> list[Frame] | None:
        """``f`` and its newest parents up to the top (cached until the topology changes); None on a loop."""
        if f.path_topology != self._topology:
            path = [f]
            cur = f
            while cur.data:
                cur = cur.data[-1][0]
                path.append(cur)
                if len(path) > MAX_GRAPH_DEPTH:
                    return None
            f.path = path
            f.index = {frame: i for i, frame in enumerate(path)}
            f.sides = {}
            f.path_topology = self._topology
        return f.path

    def _pmin(self, f: Frame) -> list[int]:
        """Prefix minima of the newest stamps along ``f.path`` (cached until the next insertion)."""
        if f.pmin_gen != self._gen:
            best = 0
            pmin = [0]
            for frame in f.path:
                lt = frame.latest
                if lt and (best == 0 or lt < best):
                    best = lt
                pmin.append(best)
            f.pmin = pmin
            f.pmin_gen = self._gen
        return f.pmin

    def _common_time(self, target: Frame, source: Frame, err: list[str] | None) -> tuple[int, int]:
        """(code, time): tf2's ``getLatestCommonTime``: the oldest of the newest stamps of the links
        below the lowest common ancestor, on both sides (static links do not count)."""
        if source is target:
            return NO_ERROR, (source.latest if source.has_cache else 0)
        m = self._meet(source, target)
        if m is not None:
            a = self._pmin(source)[m[0]]
            b = self._pmin(target)[m[1]]
            return NO_ERROR, (a if b == 0 or (a and a < b) else b)
        code, t, _ = self._common_time_walk(target, source, err)
        return code, t

    def _common_time_walk(
        self, target: Frame, source: Frame, err: list[str] | None
    ) -> tuple[int, int, list[Frame]]:
        counted: list[Frame] = []
        up: list[tuple[int, Frame, Frame]] = []  # (latest stamp, frame, its parent) from the source
        frame: Frame | None = source
        depth = 0
        while frame is not None and frame.has_cache:
            lt, parent = frame.latest_time_and_parent()
            if parent is None:
                break
            up.append((lt, frame, parent))
            frame = parent
            if frame is target:
                return NO_ERROR, _min_stamp(e[1] for e in up), [e[1] for e in up]
            depth += 1
            if depth > MAX_GRAPH_DEPTH:
                return self._loop_error(err), 0, counted
        parents = {e[2]: i for i, e in enumerate(up)}
        frame = target
        depth = 0
        common: int | None = None
        while frame.has_cache:
            lt, parent = frame.latest_time_and_parent()
            if parent is None:
                break
            counted.append(frame)
            if parent in parents:
                common = parents[parent]
                break
            frame = parent
            if frame is source:
                return NO_ERROR, _min_stamp(counted), counted
            depth += 1
            if depth > MAX_GRAPH_DEPTH:
                return self._loop_error(err), 0, counted
        if common is None:
            self._connectivity_error(source, target, err)
            return CONNECTIVITY_ERROR, 0, counted
        counted.extend(e[1] for e in up[: common + 1])
        return NO_ERROR, _min_stamp(counted), counted

    def _loop_error(self, err: list[str] | None) -> int:
        if err is not None:
            err.append(
                "The tf tree is invalid because it contains a loop.\n" + self._frames_as_string() + "\n"
            )
        return LOOKUP_ERROR

    @staticmethod
    def _connectivity_error(source: Frame, target: Frame, err: list[str] | None) -> None:
        if err is not None:
            err.append(
                f"Could not find a connection between '{target.name}' and '{source.name}' because they are not "
                "part of the same tree.Tf has two or more unconnected trees."
            )

    # -- lookups ---------------------------------------------------------------------------------
    def _to_root(self, frame: Frame, t: int, gen: int) -> tuple | None:
        """``(root, transform)``: ``frame`` expressed in the top frame of its tree at time ``t``, memoized
        per frame until the next insertion (``gen``); None when some link has no data for ``t``."""
        if frame.memo_gen == gen and frame.memo_t == t:
            return frame.memo_val
        if not frame.data:  # the top of its tree ("map", "world"): itself, at any time
            acc = (frame, (0j, 0.0, 1.0 + 0j))
            frame.memo_gen, frame.memo_t, frame.memo_val = gen, t, acc
            return acc
        path: list[tuple[Frame, Entry]] = []
        cur = frame
        acc: tuple | None
        while True:
            if cur.memo_gen == gen and cur.memo_t == t:
                acc = cur.memo_val
                break
            e = cur.at(t, None)
            if e is None:
                acc = None
                cur.memo_gen, cur.memo_t, cur.memo_val = gen, t, None
                break
            path.append((cur, e))
            parent = e[0]
            if not parent.data:  # the top of the tree (no cache, or emptied by clear)
                f, e = path.pop()
                x, y, z, qx, qy, qz, qw = e[1]
                acc = (parent, (complex(x, y), z, complex(qw, qz)) if qx == 0.0 and qy == 0.0 else e[1])
                f.memo_gen, f.memo_t, f.memo_val = gen, t, acc
                break
            cur = parent
            if len(path) > MAX_GRAPH_DEPTH:
                return None
        if acc is None:
            for f, _ in path:
                f.memo_gen, f.memo_t, f.memo_val = gen, t, None
            return None
        root, value = acc
        planar = len(value) == 3  # (P, Z, Q) as in _relative_at, else 7 floats
        if planar:
            P, Z, Q = value
        else:
            x, y, z, qx, qy, qz, qw = value
        for f, e in reversed(path):  # to_root(f) = to_root(parent) * link
            bx, by, bz, bqx, bqy, bqz, bqw = e[1]
            if planar:
                if bqx == 0.0 and bqy == 0.0:  # both planar: rotate by Q² (Q is the half angle)
                    P += Q * Q * complex(bx, by)
                    Z += bz
                    Q *= complex(bqw, bqz)
                    acc = (root, (P, Z, Q))
                    f.memo_gen, f.memo_t, f.memo_val = gen, t, acc
                    continue
                planar = False
                x = P.real
                y = P.imag
                z = Z
                qx = qy = 0.0
                qz = Q.imag
                qw = Q.real
            # as tfm.compose inline
            cx = qy * bz - qz * by + qw * bx
            cy = qz * bx - qx * bz + qw * by
            cz = qx * by - qy * bx + qw * bz
            x = x + bx + 2.0 * (qy * cz - qz * cy)
            y = y + by + 2.0 * (qz * cx - qx * cz)
            z = z + bz + 2.0 * (qx * cy - qy * cx)
            nx = qw * bqx + qx * bqw + qy * bqz - qz * bqy
            ny = qw * bqy - qx * bqz + qy * bqw + qz * bqx
            nz = qw * bqz + qx * bqy - qy * bqx + qz * bqw
            qw = qw * bqw - qx * bqx - qy * bqy - qz * bqz
            qx = nx
            qy = ny
            qz = nz
            acc = (root, (x, y, z, qx, qy, qz, qw))
            f.memo_gen, f.memo_t, f.memo_val = gen, t, acc
        return acc

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
            return self._lookup(target, source, t)

    def _lookup(self, target: Frame, source: Frame, t: int) -> tuple[int, tuple]:
        topology = self._topology
        sp = source.path if source.path_topology == topology else self._path(source)
        tp = target.path if target.path_topology == topology else self._path(target)
        gen = self._gen
        i = j = -1  # the lowest common ancestor is sp[i] and tp[j] (-1: the paths do not meet)
        if sp is not None and tp is not None and sp[-1] is tp[-1]:
            i = len(sp) - 1
            j = len(tp) - 1
            if i > 12 and j > 12:  # deep frames: bisect on depth (the ancestors at a depth match up to it)
                lo = 0
                hi = min(i, j)
                while lo < hi:
                    mid = (lo + hi + 1) >> 1
                    if sp[i - mid] is tp[j - mid]:
                        lo = mid
                    else:
                        hi = mid - 1
                i -= lo
                j -= lo
            else:
                while i and j and sp[i - 1] is tp[j - 1]:
                    i -= 1
                    j -= 1
        if t == 0:
            if i < 0:
                err: list[str] = []
                code, t = self._common_time(target, source, err)
                if code != NO_ERROR:
                    _raise(code, err)
            elif self._asked_gen == gen:  # tf2's latest common time, from cached prefix minima
                a = source.pmin[i] if source.pmin_gen == gen else self._pmin(source)[i]
                b = target.pmin[j] if target.pmin_gen == gen else self._pmin(target)[j]
                t = a if b == 0 or (a and a < b) else b
            else:  # the first lookup since an insertion (data streams in between lookups): just the sides
                self._asked_gen = gen
                t = 0
                for k in range(i):
                    b = sp[k].latest
                    if b and (t == 0 or b < t):
                        t = b
                for k in range(j):
                    b = tp[k].latest
                    if b and (t == 0 or b < t):
                        t = b
        if (source.memo_gen == gen and source.memo_t == t) or t == self._last_t:
            # a time asked for before: each frame's transform to the top of its tree is (or becomes) memoized
            a = (
                source.memo_val
                if source.memo_gen == gen and source.memo_t == t
                else self._to_root(source, t, gen)
            )
            if a is not None:
                b = (
                    target.memo_val
                    if target.memo_gen == gen and target.memo_t == t
                    else self._to_root(target, t, gen)
                )
                if b is not None and a[0] is b[0]:
                    return t, _between(a[1], b[1])
            # some link above the common ancestor has no data for t (a slow map->odom under a fast
            # odom->base_link): the answer only needs the links below it
        else:
            self._last_t = t
        # a one-off time: compose each side up to the lowest common ancestor, interpolating on the way
        if i >= 0:
            lca = sp[i]
            up = source.sides.get(lca) or _side(source, i)
            down = target.sides.get(lca) or _side(target, j)
            tr = None
            if up[0] is not None and down[0] is not None:
                a = self._side_composite(up, t)
                if a is not None:
                    b = self._side_composite(down, t)
                    if b is not None:
                        tr = _planar_between(a, b)
            if tr is None:
                tr = _relative_at(up[2], down[2], t)
            if tr is not None:
                return t, tr
        return t, self._walk_transform(target, source, t)

    def _side_composite(self, side: list, t: int) -> tuple | None:
        """One side of a frame pair (its links up to the common ancestor) at time ``t`` as ``(P, Z, Q)``
        from the side's composite for the segment around ``t``, or None (then the links are composed one
        by one). Rotations about one axis commute, so when every link of the side is planar and the
        dynamic ones share that segment's two stamps (transforms sent together, as a
        robot_state_publisher or this benchmark's broadcaster sends them), the whole side at ratio r
        is ``Q0 e^{irΘ}`` for the rotation and a sum of one term ``(F + rG) e^{irφ}`` per distinct
        angle for the translation: a composite made of the segment records once, on the second lookup
        in that segment, and valid until history changes other than at its new end
        (``_history``) or the segment is pruned (``_floor``)."""
        comps, lead, links = side
        if not links:
            return 0j, 0.0, 1.0 + 0j
        if t >= lead.latest:  # at (or past) the newest stamp: there is no segment around t
            return None
        stamps = lead.stamps
        i = bisect_right(stamps, t)
        if not i:
            return None
        t0 = stamps[i - 1]
        if t0 + lead.keep < lead.latest:  # tf2 has pruned the segment's older end
            return None
        c = comps.get(t0)
        if c is None:  # first seen: not worth a composite yet
            if len(comps) >= 256:
                comps.clear()
            comps[t0] = _SEEN
            return None
        if c[0] != self._history or t0 < self._floor:
            c = _build_composite(links, t, t0, stamps[i], self._history)
            if c is None:  # a link is not planar: never for this side
                side[0] = None
                return None
            comps[t0] = c
        _, inv, q0, theta, z0, dz, terms = c
        if q0 is None:  # the links do not share this segment
            return None
        r = (t - t0) * inv
        P = 0j
        for phi, F, G in terms:
            P += (F + r * G) * rect(1.0, r * phi) if phi else F + r * G
        return P, z0 + r * dz, q0 * rect(1.0, r * theta) if theta else q0

    def _meet(self, source: Frame, target: Frame) -> tuple[int, int] | None:
        """``(i, j)``: the lowest common ancestor of two frames along their newest parents is
        ``source.path[i]`` and ``target.path[j]`` (paths cached until the topology changes); None when
        the paths do not meet (the walk then gives tf2's error)."""
        sp = self._path(source)
        tp = self._path(target)
        if sp is None or tp is None:
            return None
        index = source.index
        for j, frame in enumerate(tp):  # noqa: B007 (j is the answer)
            i = index.get(frame)
            if i is not None:
                return i, j
        return None

    def _walk_transform(self, target: Frame, source: Frame, t: int) -> tuple:
        """tf2's ``walkToTopParent`` with ``TransformAccum``; raises tf2's error for this lookup."""
        err: list[str] = []
        code, result, _ = self._walk(target, source, t, err, accumulate=True)
        if code != NO_ERROR:
            _raise(code, err)
        return result

    def _walk(
        self, target: Frame, source: Frame, t: int, err: list[str] | None, accumulate: bool
    ) -> tuple[int, tuple, list[Frame]]:
        """(code, transform, chain): walk source->top, then target->that top, as tf2 does."""
        if source is target:
            return NO_ERROR, tfm.IDENTITY, [source]
        if t == 0:
            code, t = self._common_time(target, source, err)
            if code != NO_ERROR:
                return code, tfm.IDENTITY, []
        src_acc = tfm.IDENTITY
        tgt_acc = tfm.IDENTITY
        chain: list[Frame] = []
        extra: list[str] = []
        frame = source
        top = frame
        depth = 0
        maybe_extrapolation = False
        while True:
            chain.append(frame)
            if not frame.has_cache:
                top = frame
                break
            e = frame.at(t, extra) if accumulate else _parent_entry(frame, t, extra)
            if e is None:
                top = frame
                maybe_extrapolation = True
                break
            if frame is target:
                return NO_ERROR, src_acc, chain
            if accumulate:
                src_acc = tfm.compose(e[1], src_acc)
            top = frame
            frame = e[0]
            depth += 1
            if depth > MAX_GRAPH_DEPTH:
                return self._loop_error(err), tfm.IDENTITY, []
        frame = target
        depth = 0
        back: list[Frame] = []
        while frame is not top:
            back.append(frame)
            if not frame.has_cache:
                break
            miss: list[str] = []
            e = frame.at(t, miss) if accumulate else _parent_entry(frame, t, miss)
            if e is None:
                if err is not None:
                    err.append(
                        f"{miss[0] if miss else ''}, when looking up transform from frame [{source.name}] to "
                        f"frame [{target.name}]"
                    )
                return EXTRAPOLATION_ERROR, tfm.IDENTITY, []
            if frame is source:
                back.reverse()
                return NO_ERROR, tfm.inverse(tgt_acc), back
            if accumulate:
                tgt_acc = tfm.compose(e[1], tgt_acc)
            frame = e[0]
            depth += 1
            if depth > MAX_GRAPH_DEPTH:
                return self._loop_error(err), tfm.IDENTITY, []
        if frame is not top:
            if maybe_extrapolation:
                if err is not None:
                    err.append(
                        f"{extra[0] if extra else ''}, when looking up transform from frame [{source.name}] to "
                        f"frame [{target.name}]"
                    )
                return EXTRAPOLATION_ERROR, tfm.IDENTITY, []
            self._connectivity_error(source, target, err)
            return CONNECTIVITY_ERROR, tfm.IDENTITY, []
        # chain runs source..top and back target..(below top): both climbed to the same top, so drop
        # their shared upper part and keep the lowest common frame once (tf2's pruning)
        back.append(top)
        lca = top
        while chain and back and chain[-1] is back[-1]:
            lca = chain.pop()
            back.pop()
        back.reverse()
        full = [*chain, lca, *back]
        return NO_ERROR, tfm.inverse_compose(tgt_acc, src_acc), full

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
        try:  # the lookup's caches answer most checks without a walk
            self._lookup(target, source, t)
            return True, ""
        except TransformException:
            pass  # the walk says why, in tf2's words
        err: list[str] = []
        code, _, _ = self._walk(target, source, t, err, accumulate=False)
        return code == NO_ERROR, "".join(err)

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

    # -- text views ------------------------------------------------------------------------------
    def _frames_as_string(self) -> str:
        lines = []
        for f in self._order:
            if not f.has_cache:
                continue
            parent = f.data[-1][0].name if f.data else NO_PARENT
            lines.append(f"Frame {f.name} exists with parent {parent}.\n")
        return "".join(lines)

    def all_frames_as_string(self) -> str:
        """tf2's ``allFramesAsString``: one "Frame x exists with parent y." line per child frame."""
        self._pull()
        with self._lock:
            self._drain()
            return self._frames_as_string()

    def _stats(self, f: Frame) -> tuple[str, float, float, float, float]:
        """(parent name, rate, newest, oldest, buffer length) of a frame with data, as tf2 computes them."""
        latest = _secs(f.latest)
        oldest = _secs(f.oldest())
        rate = len(f.data) / max(latest - oldest, 0.0001)
        return f.data[-1][0].name, rate, latest, oldest, _secs(f.latest - f.oldest())

    def all_frames_as_yaml(self, current_time: float = 0.0) -> str:
        """tf2's ``allFramesAsYAML`` (what ``tf2_frames`` and view_frames read)."""
        self._pull()
        with self._lock:
            self._drain()
            out = [] if self._order else ["{}"]
            for f in self._order:
                if not f.has_cache or not f.data:
                    continue
                parent, rate, latest, oldest, length = self._stats(f)
                out.append(
                    f"{f.name}: \n  parent: '{parent}'\n  broadcaster: '{f.authority or 'no recorded authority'}'\n"
                    f"  rate: {rate:.3f}\n  most_recent_transform: {latest:.3f}\n  oldest_transform: {oldest:.3f}\n"
                )
                if current_time > 0:
                    out.append(f"  transform_delay: {current_time - latest:.3f}\n")
                out.append(f"  buffer_length: {length:.3f}\n")
            return "".join(out)

    def all_frames_as_dot(self, current_time: float = 0.0) -> str:
        """tf2's ``_allFramesAsDot``: the frame tree for Graphviz, with tf2's labels."""
        self._pull()
        with self._lock:
            self._drain()
            out = ["digraph G {\n"]
            if not self._order:
                out.append('"no tf data recieved"')
            for f in self._order:
                if not f.has_cache or not f.data:
                    continue
                parent, rate, latest, _, length = self._stats(f)
                age = f"( {current_time - latest:.3f} sec old)" if current_time > 0 else ""
                out.append(
                    f'"{parent}" -> "{f.name}"[label="Broadcaster: {f.authority or "no recorded authority"}\\n'
                    f"Average rate: {rate:.3f} Hz\\nMost recent transform: {latest:.3f} {age}\\n"
                    f'Buffer length: {length:.3f} sec\\n"];\n'
                )
            legend = ' subgraph cluster_legend { style=bold; color=black; label ="view_frames Result";\n'
            for f in self._order:
                if not f.has_cache:
                    if current_time > 0:
                        out.append(
                            f'edge [style=invis];\n{legend}"Recorded at time: {current_time:.3f}"[ shape=plaintext ] ;\n'
                            f' }}->"{f.name}";\n'
                        )
                    continue
                if not f.data:
                    out.append("edge [style=invis];\n" + legend)
                    if current_time > 0:
                        out.append(f'"Recorded at time: {current_time:.3f}"[ shape=plaintext ] ;\n ')
                    out.append(f'}}->"{f.name}";\n')
            out.append("}")
            return "".join(out)


def _nlerp(
    ax: float, ay: float, az: float, aw: float, dx: float, dy: float, dz: float, dw: float, r: float
) -> tuple[float, float, float, float]:
    """``A + r (B - A)`` normalized: slerp where A and B are too close for its sine (see Frame._segment)."""
    qx = ax + r * dx
    qy = ay + r * dy
    qz = az + r * dz
    qw = aw + r * dw
    k = 1.0 / sqrt(qx * qx + qy * qy + qz * qz + qw * qw)
    return qx * k, qy * k, qz * k, qw * k


def _relative_at(up: tuple, down: tuple, t: int) -> tuple | None:
    """The transform from frame ``up[0][0]`` into ``down[0][0]`` at time ``t``, through their lowest common
    ancestor: ``up`` and ``down`` are each side's links ``(frame, its parent)`` from the frame to that
    ancestor. Each link is interpolated from its segment record (:meth:`Frame._segment`) and composed
    onto its side's transform in place; the two sides then meet in one ``inverse(down) * up``. None
    when a link has no data for ``t`` or another parent then: the exact walk decides those cases.

    This is one lookup's hot loop, kept in one function (calls cost more than the arithmetic). While
    every link so far is planar (rotations about z only, the usual case for a mobile robot's links)
    a side is a complex translation ``x + iy``, a float z and a complex rotation ``w + iz``: composing
    a link is three complex operations instead of about sixty float ones. The first non-planar link
    turns its side into the general form ``(x, y, z, qx, qy, qz, qw)`` for the links after it."""
    sides = []
    for links in (up, down):
        planar = True  # this side is (P, Z, Q); else (x, y, z, qx, qy, qz, qw)
        P = 0j
        Z = 0.0
        Q = 1.0 + 0j
        x = y = z = qx = qy = qz = qw = 0.0
        for f, parent in links:
            if f.static or f.latest == t:  # the newest entry as it is (a static frame's only one)
                d = f.data[-1]
                if len(d) == 3:
                    d = f._resolve(-1)
                if d[0] is not parent:
                    return None
                ex, ey, ez, px, py, pz, pw = d[1]
                if planar and px == 0.0 and py == 0.0:
                    c = complex(pw, pz)
                    P = c * c * P + complex(ex, ey)
                    Z += ez
                    Q = c * Q
                    continue
            else:
                stamps = f.stamps
                i = bisect_right(stamps, t)
                if not (0 < i < len(stamps) and stamps[i - 1] + f.keep >= f.latest):
                    return None  # before the oldest (kept) or after the newest stamp: extrapolation
                rec = f.segs[i] or f._segment(i)
                if rec[1] is not parent:
                    return None
                r = (t - rec[2]) * rec[3]
                if rec[0]:  # a planar link
                    _, _, _, _, e, ez, de, dz, c, th = rec
                    if r:
                        e += r * de
                        ez += r * dz
                        if th:
                            c *= rect(1.0, r * th)
                    if planar:  # link * side: rotate by c² (c is the half angle), then translate
                        P = c * c * P + e
                        Z += ez
                        Q = c * Q
                        continue
                    ex = e.real
                    ey = e.imag
                    px = py = 0.0
                    pz = c.imag
                    pw = c.real
                else:
                    _, _, _, _, ex, ey, ez, dx, dy, dz, px, py, pz, pw, cx, cy, cz, cw, th = rec
                    if r:
                        ex += r * dx
                        ey += r * dy
                        ez += r * dz
                        if th:
                            a = r * th
                            co = cos(a)
                            si = sin(a)
                            px = px * co + cx * si
                            py = py * co + cy * si
                            pz = pz * co + cz * si
                            pw = pw * co + cw * si
                        else:
                            px, py, pz, pw = _nlerp(px, py, pz, pw, cx, cy, cz, cw, r)
            if planar:  # the first general link: the side continues in the 7-float form
                planar = False
                x = P.real
                y = P.imag
                z = Z
                qz = Q.imag
                qw = Q.real
            # link * side, as tfm.compose (plain assignments: no tuple per link)
            ux = py * z - pz * y + pw * x
            uy = pz * x - px * z + pw * y
            uz = px * y - py * x + pw * z
            x = ex + x + 2.0 * (py * uz - pz * uy)
            y = ey + y + 2.0 * (pz * ux - px * uz)
            z = ez + z + 2.0 * (px * uy - py * ux)
            nx = pw * qx + px * qw + py * qz - pz * qy
            ny = pw * qy - px * qz + py * qw + pz * qx
            nz = pw * qz + px * qy - py * qx + pz * qw
            qw = pw * qw - px * qx - py * qy - pz * qz
            qx = nx
            qy = ny
            qz = nz
        sides.append((P, Z, Q) if planar else (x, y, z, qx, qy, qz, qw))
    return _between(sides[0], sides[1])


def _between(a: tuple, b: tuple) -> tuple:
    """``inverse(b) * a`` as 7 floats, for transforms each planar ``(P, Z, Q)`` or 7 floats."""
    if len(a) == 3 and len(b) == 3:
        return _planar_between(a, b)
    if len(a) == 3:
        a = (a[0].real, a[0].imag, a[1], 0.0, 0.0, a[2].imag, a[2].real)
    if len(b) == 3:
        b = (b[0].real, b[0].imag, b[1], 0.0, 0.0, b[2].imag, b[2].real)
    return tfm.inverse_compose(b, a)


def _side(frame: Frame, n: int) -> list:
    """``frame.sides`` entry for its ancestor ``frame.path[n]`` (made on first use)."""
    path = frame.path
    links = tuple(zip(path[:n], path[1 : n + 1], strict=True))
    lead = next((f for f, _ in links if not f.static), None)
    side = [None if links and lead is None else {}, lead, links]
    frame.sides[path[n]] = side
    return side


def _planar_between(a: tuple, b: tuple) -> tuple:
    """``inverse(b) * a`` for two planar sides ``(P, Z, Q)``, as 7 floats."""
    P, Z, Q = a
    Pb, Zb, Qb = b
    Qb = Qb.conjugate()
    P = Qb * Qb * (P - Pb)
    Q = Qb * Q
    return P.real, P.imag, Z - Zb, 0.0, 0.0, Q.imag, Q.real


def _build_composite(links: tuple, t: int, t0: int, t1: int, history: int) -> tuple | None:
    """``(history, 1/(t1 - t0), Q0, Θ, Z0, dZ, terms)``: a planar side over the segment t0..t1 (see
    :meth:`BufferCore._side_composite`); the same with Q0 None when a link has another parent then or
    its segment around ``t`` is not t0..t1; None when a link is not planar. Built from the top link down: the rotation above link k
    (the product of the A² of the links above it, and the sum of their 2θ) multiplies its translation."""
    recs = []
    for f, parent in links:
        if f.static:
            rec = f._point()
        else:
            stamps = f.stamps
            i = bisect_right(stamps, t)
            if not 0 < i < len(stamps) or stamps[i - 1] != t0 or stamps[i] != t1 or t0 + f.keep < f.latest:
                return (history, 0.0, None, 0.0, 0.0, 0.0, ())
            rec = f.segs[i] or f._segment(i)
            if not rec[3]:  # a change of parent inside the segment
                return (history, 0.0, None, 0.0, 0.0, 0.0, ())
        if rec[1] is not parent:
            return (history, 0.0, None, 0.0, 0.0, 0.0, ())
        if not rec[0]:
            return None
        recs.append(rec)
    above = 1.0 + 0j  # the rotation of the links above, squared (it turns translations)
    phi = 0.0
    q0 = 1.0 + 0j
    theta = z0 = dz = 0.0
    terms: dict[float, list[complex]] = {}
    for rec in reversed(recs):
        _, _, _, _, e, ez, de, dzk, c, th = rec
        term = terms.setdefault(phi, [0j, 0j])
        term[0] += above * e
        term[1] += above * de
        above *= c * c
        phi += 2.0 * th
        q0 *= c
        theta += th
        z0 += ez
        dz += dzk
    flat = tuple((p, fg[0], fg[1]) for p, fg in terms.items())
    return history, 1.0 / (t1 - t0), q0, theta, z0, dz, flat


def _min_stamp(frames: Iterable[Frame]) -> int:
    best = 0
    for f in frames:
        lt = f.latest
        if lt and (best == 0 or lt < best):
            best = lt
    return best


def _parent_entry(frame: Frame, t: int, err: list[str] | None) -> Entry | None:
    """What ``CanTransformAccum.gather`` needs: the parent at ``t`` (as a 1-tuple), or None."""
    p = frame.parent_at(t, err)
    return None if p is None else (p,)


def _raise(code: int, err: list[str]) -> None:
    text = "".join(err)
    if code == CONNECTIVITY_ERROR:
        raise ConnectivityException(text)
    if code == EXTRAPOLATION_ERROR:
        raise ExtrapolationException(text)
    if code == LOOKUP_ERROR:
        raise LookupException(text)
    raise TimeoutException(text)


__all__ = ["BufferCore", "Frame", "DEFAULT_CACHE_TIME"]

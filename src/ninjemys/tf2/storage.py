"""tf2's frames and their time caches (``tf2::TimeCache``/``StaticCache``), and the state every part of the
buffer core shares: frame names, newest-parent paths, change notification. The rules are in
:mod:`ninjemys.tf2.core`.
"""

from __future__ import annotations

import logging
import threading
from bisect import bisect_left
from cmath import rect
from collections.abc import Callable
from math import acos, atan2, cos, sin, sqrt
from typing import Any

from ninjemys.tf2.bulk import Layout
from ninjemys.tf2.errors import (
    ConnectivityException,
    ExtrapolationException,
    InvalidArgumentException,
    LookupException,
    TimeoutException,
)

_log = logging.getLogger("ninjemys.tf2.core")

DEFAULT_CACHE_TIME = 10.0
MAX_GRAPH_DEPTH = 1000
NO_PARENT = "NO_PARENT"

# tf2_msgs/TF2Error codes, as walk results
NO_ERROR = 0
LOOKUP_ERROR = 1
CONNECTIVITY_ERROR = 2
EXTRAPOLATION_ERROR = 3

Entry = tuple  # (parent: Frame, (tx, ty, tz, qx, qy, qz, qw))
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


def _raise(code: int, err: list[str]) -> None:
    text = "".join(err)
    if code == CONNECTIVITY_ERROR:
        raise ConnectivityException(text)
    if code == EXTRAPOLATION_ERROR:
        raise ExtrapolationException(text)
    if code == LOOKUP_ERROR:
        raise LookupException(text)
    raise TimeoutException(text)


class FrameStore:
    """The frames and the shared state of :class:`~ninjemys.tf2.core.BufferCore` (one lock, one condition):
    the base every part of the core (ingest, reference lookup, fast path, introspection) builds on."""

    def __init__(
        self, cache_time: float = DEFAULT_CACHE_TIME, report: Reporter | None = None, fast: bool = True
    ) -> None:
        """``cache_time`` is seconds of history per frame; ``report`` receives the one line about bad input
        (default: the core's logger at error level); ``fast`` picks the lookup path (see BufferCore)."""
        self.fast = fast
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

    def _frame_or_new(self, name: str) -> Frame:
        f = self._frames.get(name)
        if f is None:
            f = Frame(name, len(self._order) + 1, self.cache_time_ns)
            self._frames[name] = f
            self._order.append(f)
            self._topology += 1
        return f

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

    def _frames_as_string(self) -> str:
        lines = []
        for f in self._order:
            if not f.has_cache:
                continue
            parent = f.data[-1][0].name if f.data else NO_PARENT
            lines.append(f"Frame {f.name} exists with parent {parent}.\n")
        return "".join(lines)

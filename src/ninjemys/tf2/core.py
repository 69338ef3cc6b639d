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
- ``can_transform`` with a timeout waits on a condition that insertions signal (no polling sleeps).

Times are integer nanoseconds in this module's fast API (``lookup``, ``set_transforms``); the
message-level API (``lookup_transform_core`` ...) takes and returns ``ninjemys.rostime`` values.
"""

from __future__ import annotations

import logging
import threading
import time as _wall
from bisect import bisect_left
from collections.abc import Callable, Iterable, Sequence
from math import isfinite

from ninjemys.tf2 import math as tfm
from ninjemys.tf2.errors import (
    ConnectivityException,
    ExtrapolationException,
    InvalidArgumentException,
    LookupException,
    TimeoutException,
    TransformException,
)

_log = logging.getLogger(__name__)

DEFAULT_CACHE_TIME = 10.0
MAX_GRAPH_DEPTH = 1000
QUATERNION_TOLERANCE = 10e-6  # tf2: |x²+y²+z²+w² - 1| must stay under this
NO_PARENT = "NO_PARENT"
REPEAT_REPORT_AFTER = 10.0  # seconds before the same bad-input line is reported again

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
        "static",
        "has_cache",
        "stamps",
        "data",
        "latest",
        "parent",
        "authority",
        "memo_gen",
        "memo_t",
        "memo_val",
        "quiet_repeat",
        "warned_old",
    )

    def __init__(self, name: str, number: int) -> None:
        self.name = name
        self.number = number
        self.static = False
        self.has_cache = False  # tf2: frames_[id] is null until the frame is somebody's child
        self.stamps: list[int] = []  # ascending
        self.data: list[Entry] = []
        self.latest = 0  # newest stamp (0 for static frames, as tf2's StaticCache says)
        self.parent: Frame | None = None  # parent of the newest entry
        self.authority = ""
        self.memo_gen = -1
        self.memo_t = -1
        self.memo_val: tuple | None = None
        self.quiet_repeat = False
        self.warned_old = 0.0

    def __repr__(self) -> str:
        return f"Frame({self.name!r})"

    # -- tf2's TimeCache -------------------------------------------------------------------------
    def at(self, t: int, err: list[str] | None) -> Entry | None:
        """The entry for time ``t`` (0 = newest), interpolated; None (and a tf2 text in ``err``) if none."""
        data = self.data
        if not data:
            return None
        if self.static or t == 0:
            return data[-1]
        stamps = self.stamps
        n = len(stamps)
        if n == 1:
            if stamps[0] == t:
                return data[0]
            if err is not None:
                err.append(
                    "Lookup would require extrapolation at time %.09f, but only time %.09f is in the buffer"
                    % (_secs(t), _secs(stamps[0]))
                )
            return None
        latest = stamps[-1]
        if t == latest:
            return data[-1]
        earliest = stamps[0]
        if t == earliest:
            return data[0]
        if t > latest:
            if err is not None:
                err.append(
                    "Lookup would require extrapolation %.09fs into the future.  Requested time %.09f but the "
                    "latest data is at time %.09f" % (_secs(t - latest), _secs(t), _secs(latest))
                )
            return None
        if t < earliest:
            if err is not None:
                err.append(
                    "Lookup would require extrapolation %.09fs into the past.  Requested time %.09f but the "
                    "earliest data is at time %.09f" % (_secs(earliest - t), _secs(t), _secs(earliest))
                )
            return None
        i = bisect_left(stamps, t)
        if stamps[i] == t:
            return data[i]
        older = data[i - 1]
        newer = data[i]
        if older[0] is not newer[0]:  # the parent changed in between: tf2 keeps the older one
            return older
        t0 = stamps[i - 1]
        ratio = (t - t0) / (stamps[i] - t0)
        return older[0], tfm.interpolate(older[1], newer[1], ratio)

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
        return 0 if self.static or not self.stamps else self.stamps[0]


class _Pair:
    """The frames whose newest stamps decide a pair's latest common time (tf2's ``getLatestCommonTime``)."""

    __slots__ = ("topology", "frames", "gen", "time")

    def __init__(self, topology: int, frames: list[Frame]) -> None:
        self.topology = topology
        self.frames = frames
        self.gen = -1
        self.time = 0


class BufferCore:
    """tf2's BufferCore: set transforms in, look transforms up. Thread-safe (one lock, one condition)."""

    def __init__(self, cache_time: float = DEFAULT_CACHE_TIME, report: Reporter | None = None) -> None:
        """``cache_time`` is seconds of history per frame; ``report`` receives the one line about bad input
        (default: this module's logger at error level)."""
        self.cache_time_ns = int(round(cache_time * 1e9))
        self._report: Reporter = report or _log.error
        self._frames: dict[str, Frame] = {}
        self._order: list[Frame] = []  # by frame number (tf2's frameIDs_reverse, minus NO_PARENT)
        self._lock = threading.RLock()
        self._changed = threading.Condition(self._lock)
        self._waiters = 0
        self._gen = 0  # bumped by every accepted insertion: memos of older generations are stale
        self._topology = 0  # bumped when a frame appears or a newest parent changes
        self._pairs: dict[tuple[Frame, Frame], _Pair] = {}
        self._listeners: list[Callable[[], None]] = []
        self._reported: dict[str, float] = {}

    @property
    def cache_time(self) -> float:
        return self.cache_time_ns / 1e9

    # -- frames ----------------------------------------------------------------------------------
    def _frame_or_new(self, name: str) -> Frame:
        f = self._frames.get(name)
        if f is None:
            f = Frame(name, len(self._order) + 1)
            self._frames[name] = f
            self._order.append(f)
            self._topology += 1
        return f

    def frame_exists(self, name: str) -> bool:
        """tf2's ``_frameExists``: the name is known (as a child or as a parent)."""
        with self._lock:
            return name in self._frames

    def frame_names(self) -> list[str]:
        """Every known frame, in the order tf2 numbered them (``_getFrameStrings``)."""
        with self._lock:
            return [f.name for f in self._order]

    def add_change_listener(self, fn: Callable[[], None]) -> None:
        """Call ``fn()`` (on the inserting thread, outside the lock) after every batch of accepted data."""
        self._listeners.append(fn)

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
            for item in items:
                why = self._insert(item, authority, is_static)
                if why is None:
                    accepted += 1
                elif why:
                    problems.append(why)
            if accepted:
                self._gen += 1
                if self._waiters:
                    self._changed.notify_all()
        if problems:
            self._report_once(problems)
        if accepted:
            for fn in self._listeners:
                fn()
        return accepted

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
        if not child.has_cache:
            child.has_cache = True
            child.static = is_static
        child.authority = authority
        if child.static:
            if not child.data or child.data[-1][0] is not parent:
                self._topology += 1
            child.data = [entry]
            child.stamps = [stamp]
            child.parent = parent
            return None
        stamps = child.stamps
        if not stamps or stamp > stamps[-1]:
            if child.parent is not parent:
                self._topology += 1
                child.parent = parent
            stamps.append(stamp)
            child.data.append(entry)
            child.latest = stamp
            cutoff = stamp - self.cache_time_ns
            if stamps[0] < cutoff:
                i = bisect_left(stamps, cutoff)
                del stamps[:i]
                del child.data[:i]
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
        with self._lock:
            for f in self._order:
                if f.has_cache and not f.static:
                    f.stamps = []
                    f.data = []
                    f.latest = 0
                    f.parent = None
            self._gen += 1
            self._topology += 1
            self._pairs.clear()

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
    def _common_time(self, target: Frame, source: Frame, err: list[str] | None) -> tuple[int, int]:
        """(code, time): tf2's ``getLatestCommonTime``, with the deciding frames cached per pair."""
        if source is target:
            return NO_ERROR, (source.latest if source.has_cache else 0)
        key = (target, source)
        pair = self._pairs.get(key)
        gen = self._gen
        if pair is not None and pair.topology == self._topology:
            if pair.gen == gen:
                return NO_ERROR, pair.time
            best = 0
            for f in pair.frames:
                lt = f.latest
                if lt and (best == 0 or lt < best):
                    best = lt
            pair.gen = gen
            pair.time = best
            return NO_ERROR, best
        code, t, frames = self._common_time_walk(target, source, err)
        if code == NO_ERROR:
            if len(self._pairs) > 100_000:
                self._pairs.clear()
            pair = _Pair(self._topology, frames)
            pair.gen = gen
            pair.time = t
            self._pairs[key] = pair
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
                acc = (parent, e[1])
                f.memo_gen, f.memo_t, f.memo_val = gen, t, acc
                break
            cur = parent
            if len(path) > MAX_GRAPH_DEPTH:
                return None
        compose = tfm.compose
        for f, e in reversed(path):
            if acc is not None:
                acc = (acc[0], compose(acc[1], e[1]))
            f.memo_gen, f.memo_t, f.memo_val = gen, t, acc
        return acc

    def lookup(self, target_frame: str, source_frame: str, t: int) -> tuple[int, tuple]:
        """``(stamp_ns, 7 floats)``: the transform that maps data in ``source_frame`` into ``target_frame``
        at time ``t`` (0 = latest common). Raises tf2's exceptions with tf2's texts."""
        with self._lock:
            if target_frame == source_frame:
                if t == 0:
                    f = self._frames.get(target_frame)
                    t = f.latest if f is not None and f.has_cache else 0
                return t, tfm.IDENTITY
            target = self._validate("lookupTransform argument target_frame", target_frame)
            source = self._validate("lookupTransform argument source_frame", source_frame)
            return self._lookup(target, source, t)

    def _lookup(self, target: Frame, source: Frame, t: int) -> tuple[int, tuple]:
        if t == 0:
            err: list[str] = []
            code, t = self._common_time(target, source, err)
            if code != NO_ERROR:
                _raise(code, err)
        gen = self._gen
        a = self._to_root(source, t, gen)
        if a is not None:
            b = self._to_root(target, t, gen)
            if b is not None and a[0] is b[0]:
                return t, tfm.inverse_compose(b[1], a[1])
        return t, self._walk_transform(target, source, t)

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
        with self._lock:
            self._validate("lookupTransform argument target_frame", target_frame)
            self._validate("lookupTransform argument source_frame", source_frame)
            self._validate("lookupTransform argument fixed_frame", fixed_frame)
            _, first = self.lookup(fixed_frame, source_frame, source_t)
            stamp, second = self.lookup(target_frame, fixed_frame, target_t)
            return stamp, tfm.compose(second, first)

    def can_transform(self, target_frame: str, source_frame: str, t: int) -> tuple[bool, str]:
        """tf2's ``canTransform`` with its error text: (possible, why not)."""
        if target_frame == source_frame:
            return True, ""
        if self._warn_frame_id("canTransform argument target_frame", target_frame) or self._warn_frame_id(
            "canTransform argument source_frame", source_frame
        ):
            return False, ""
        with self._lock:
            target = self._frames.get(target_frame)
            source = self._frames.get(source_frame)
            if target is None or source is None:
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
        if t != 0:  # the memo answers most checks without a walk
            gen = self._gen
            a = self._to_root(source, t, gen)
            if a is not None:
                b = self._to_root(target, t, gen)
                if b is not None and a[0] is b[0]:
                    return True, ""
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
        with self._lock:
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
        with self._lock:
            self._waiters += 1
            try:
                while True:
                    ok, why = check()
                    current = clock()
                    if ok or current >= deadline or current + 3.0 < start or (cancelled and cancelled()):
                        return ok, why
                    self._changed.wait(min(deadline - current, 1.0) if cancelled else deadline - current)
            finally:
                self._waiters -= 1

    def wake_waiters(self) -> None:
        """Wake every ``wait_for_transform`` so it re-checks (e.g. at shutdown or after a clock jump)."""
        with self._lock:
            self._changed.notify_all()

    def latest_common_time(self, target_frame: str, source_frame: str) -> int:
        """tf2_py's ``get_latest_common_time`` (raises LookupException / TransformException)."""
        with self._lock:
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
        with self._lock:
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
        with self._lock:
            return self._frames_as_string()

    def _stats(self, f: Frame) -> tuple[str, float, float, float, float]:
        """(parent name, rate, newest, oldest, buffer length) of a frame with data, as tf2 computes them."""
        latest = _secs(f.latest)
        oldest = _secs(f.oldest())
        rate = len(f.data) / max(latest - oldest, 0.0001)
        return f.data[-1][0].name, rate, latest, oldest, _secs(f.latest - f.oldest())

    def all_frames_as_yaml(self, current_time: float = 0.0) -> str:
        """tf2's ``allFramesAsYAML`` (what ``tf2_frames`` and view_frames read)."""
        with self._lock:
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
        with self._lock:
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

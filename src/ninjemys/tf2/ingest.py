"""Putting transforms into the buffer core: checked single inserts (tf2's ``setTransform`` rules and
texts), raw TFMessages queued and decoded in batches (runs of one layout with numpy, see
:mod:`ninjemys.tf2.bulk`), batches owed to frames until a query reads them, pruning to ``cache_time``.
"""

from __future__ import annotations

import logging
import time as _wall
from bisect import bisect_left
from collections import deque
from collections.abc import Iterable, Sequence
from itertools import repeat
from math import isfinite
from operator import attrgetter, itemgetter, lt
from typing import Any

from ninjemys.errors import DeserializationError
from ninjemys.tf2.bulk import Layout, valid
from ninjemys.tf2.storage import Frame, FrameStore, _secs
from ninjemys.tf2.wire import decode_tf_message

_log = logging.getLogger("ninjemys.tf2.core")

QUATERNION_TOLERANCE = 10e-6  # tf2: |x²+y²+z²+w² - 1| must stay under this
REPEAT_REPORT_AFTER = 10.0  # seconds before the same bad-input line is reported again
PENDING_MAX = 50  # raw messages queued before the listener's thread decodes them itself
OWED_BATCHES = 4096  # batches a layout may owe its frames (they expire after cache_time)
BULK_MIN = 2  # a run this long of one layout is decoded with numpy; a single message per transform

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


class Ingest(FrameStore):
    """Insertion, the raw queue and clearing."""

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

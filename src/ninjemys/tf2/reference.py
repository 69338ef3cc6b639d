"""tf2's own lookup: ``walkToTopParent`` with ``TransformAccum``/``CanTransformAccum`` and
``getLatestCommonTime``, frame by frame, with tf2's error texts. It is the answer of record: the fast
path (:mod:`ninjemys.tf2.fastpath`) falls back to it, and ``BufferCore(fast=False)`` uses only it, so
the differential tests can compare both.
"""

from __future__ import annotations

from collections.abc import Iterable

from ninjemys.tf2 import math as tfm
from ninjemys.tf2.storage import (
    CONNECTIVITY_ERROR,
    EXTRAPOLATION_ERROR,
    LOOKUP_ERROR,
    MAX_GRAPH_DEPTH,
    NO_ERROR,
    Entry,
    Frame,
    FrameStore,
    _raise,
)


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


class ReferenceLookup(FrameStore):
    """tf2's walks over the frames (lock held by the caller)."""

    def _common_time(self, target: Frame, source: Frame, err: list[str] | None) -> tuple[int, int]:
        """(code, time): tf2's ``getLatestCommonTime``: the oldest of the newest stamps of the links
        below the lowest common ancestor, on both sides (static links do not count), by tf2's walk."""
        if source is target:
            return NO_ERROR, (source.latest if source.has_cache else 0)
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

    def _walk_time(self, target: Frame, source: Frame, t: int) -> tuple[int, tuple]:
        """``(stamp, transform)`` by tf2's walk alone, time 0 resolved to the latest common time first (what
        ``BufferCore(fast=False)`` answers lookups with)."""
        if t == 0:
            err: list[str] = []
            code, t = self._common_time(target, source, err)
            if code != NO_ERROR:
                _raise(code, err)
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

"""The fast lookup: per-frame memos of the transform to the top of the tree, per-segment interpolation
records, planar links as complex numbers and per-side composites (see :mod:`ninjemys.tf2.core` for the
rules). Every answer equals tf2's walk (:mod:`ninjemys.tf2.reference`) to rounding; where the fast path
cannot answer, the walk does.
"""

from __future__ import annotations

from bisect import bisect_right
from cmath import rect
from math import cos, sin
from typing import Any

from ninjemys.tf2 import math as tfm
from ninjemys.tf2.reference import ReferenceLookup
from ninjemys.tf2.storage import (
    MAX_GRAPH_DEPTH,
    NO_ERROR,
    Entry,
    Frame,
    _nlerp,
    _raise,
)

_SEEN = (-1,)  # a segment looked up once: its composite is made on the second lookup (no history is -1)


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
    side: list = [None if links and lead is None else {}, lead, links]
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


class FastLookup(ReferenceLookup):
    """The memoized and composed lookups (lock held by the caller)."""

    def _common_time(self, target: Frame, source: Frame, err: list[str] | None) -> tuple[int, int]:
        """(code, time): tf2's ``getLatestCommonTime``: the oldest of the newest stamps of the links
        below the lowest common ancestor, on both sides (static links do not count)."""
        if source is target or not self.fast:
            return super()._common_time(target, source, err)
        m = self._meet(source, target)
        if m is not None:  # the cached prefix minima along the newest-parent paths answer it
            a = self._pmin(source)[m[0]]
            b = self._pmin(target)[m[1]]
            return NO_ERROR, (a if b == 0 or (a and a < b) else b)
        return super()._common_time(target, source, err)

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

    def _to_root(self, frame: Frame, t: int, gen: int) -> tuple | None:
        """``(root, transform)``: ``frame`` expressed in the top frame of its tree at time ``t``, memoized
        per frame until the next insertion (``gen``); None when some link has no data for ``t``."""
        if frame.memo_gen == gen and frame.memo_t == t:
            return frame.memo_val
        acc: Any
        if not frame.data:  # the top of its tree ("map", "world"): itself, at any time
            acc = (frame, (0j, 0.0, 1.0 + 0j))
            frame.memo_gen, frame.memo_t, frame.memo_val = gen, t, acc
            return acc
        path: list[tuple[Frame, Entry]] = []
        cur = frame
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

    def _lookup(self, target: Frame, source: Frame, t: int) -> tuple[int, tuple]:
        # names reused for speed: paths (None only when i < 0), then stamps, then memos and composites
        sp: Any
        tp: Any
        a: Any
        b: Any
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

"""The buffer's lookup caches stay right when the data under them changes.

Lookups keep per-segment interpolation records (Frame.segs), per-frame paths to the top of the tree
(rebuilt on topology changes), prefix minima of the newest stamps and per-frame memos of the
transform to the top (both per insertion). Each test fills those caches, changes the data (an
out-of-order insert, a repeated stamp, pruning, a static update, a new parent, clear, batched raw
messages) and checks the next answers against an independent computation or a fresh buffer that
never cached anything.
"""

from __future__ import annotations

import math
import random

import pytest

from ninjemys.tf2 import math as tfm
from ninjemys.tf2.core import BufferCore
from ninjemys.tf2.errors import TransformException

S = 1_000_000_000


def yaw_q(yaw: float) -> tuple[float, float, float, float]:
    return (0.0, 0.0, math.sin(yaw / 2), math.cos(yaw / 2))


def tilt_q(a: float) -> tuple[float, float, float, float]:
    """A rotation about a skew axis (not only yaw), so slerp is exercised in 3D."""
    n = math.sqrt(3.0)
    s = math.sin(a / 2) / n
    return (s, s, s, math.cos(a / 2))


def item(parent: str, child: str, t: float, x: float = 0.0, q=(0.0, 0.0, 0.0, 1.0)) -> tuple:
    return (parent, child, int(round(t * S)), x, 2 * x, -x, *q)


def expected(a: tuple, b: tuple, t: float) -> tuple:
    """tf2's interpolation between two items, computed independently (lerp + tfm.slerp)."""
    r = (t * S - a[2]) / (b[2] - a[2])
    trans = tuple(a[3 + k] + r * (b[3 + k] - a[3 + k]) for k in range(3))
    return trans + tfm.slerp(a[6:], b[6:], r)


def same(got: tuple, want: tuple) -> None:
    assert got == pytest.approx(want, abs=1e-12)


def test_out_of_order_insert_splits_a_cached_segment():
    b = BufferCore()
    one, three = item("a", "b", 1, 1.0, tilt_q(0.2)), item("a", "b", 3, 3.0, tilt_q(1.4))
    b.set_transforms([one, three])
    same(b.lookup("a", "b", 2 * S)[1], expected(one, three, 2))  # caches the 1..3 segment
    two = item("a", "b", 2, -5.0, tilt_q(-0.7))
    b.set_transforms([two])
    same(b.lookup("a", "b", int(1.5 * S))[1], expected(one, two, 1.5))
    same(b.lookup("a", "b", int(2.5 * S))[1], expected(two, three, 2.5))
    same(b.lookup("a", "b", 2 * S)[1], expected(two, three, 2))


def test_repeated_stamp_replaces_both_neighbouring_segments():
    b = BufferCore()
    items = [item("a", "b", t, t, yaw_q(0.3 * t)) for t in (1, 2, 3)]
    b.set_transforms(items)
    for t in (1.5, 2.5):
        b.lookup("a", "b", int(t * S))
    new_two = item("a", "b", 2, 9.0, tilt_q(2.0))
    b.set_transforms([new_two])
    same(b.lookup("a", "b", int(1.5 * S))[1], expected(items[0], new_two, 1.5))
    same(b.lookup("a", "b", int(2.5 * S))[1], expected(new_two, items[2], 2.5))
    new_one = item("a", "b", 1, -1.0, tilt_q(-1.0))  # the oldest entry: only the segment after it
    b.set_transforms([new_one])
    same(b.lookup("a", "b", int(1.25 * S))[1], expected(new_one, new_two, 1.25))


def test_pruning_keeps_records_aligned():
    b = BufferCore(cache_time=1.0)
    items = [item("a", "b", 0.1 * k, 0.1 * k, tilt_q(0.05 * k)) for k in range(200)]
    for k, it in enumerate(items):
        b.set_transforms([it])
        if k > 2:  # interpolate inside the newest segments as history is pruned under them
            same(b.lookup("a", "b", it[2] - S // 20)[1], expected(items[k - 1], it, 0.1 * k - 0.05))
    with pytest.raises(TransformException, match="into the past"):
        b.lookup("a", "b", 5 * S)


def test_static_update_and_parent_change_are_seen():
    b = BufferCore()
    b.set_transforms([item("map", "odom", 1, 1.0), item("map", "odom", 2, 2.0)])
    b.set_transforms([item("odom", "laser", 0, 0.5)], is_static=True)
    assert b.lookup("map", "laser", int(1.5 * S))[1][0] == pytest.approx(2.0)
    b.set_transforms([item("odom", "laser", 0, 0.25)], is_static=True)
    assert b.lookup("map", "laser", int(1.5 * S))[1][0] == pytest.approx(1.75)
    # the static link moves under another parent: the cached path must follow
    b.set_transforms([item("map", "base", 1, 10.0), item("map", "base", 2, 20.0)])
    b.set_transforms([item("base", "laser", 0, 0.25)], is_static=True)
    assert b.lookup("map", "laser", int(1.5 * S))[1][0] == pytest.approx(15.25)
    assert b.lookup("odom", "laser", int(1.5 * S))[1][0] == pytest.approx(15.25 - 1.5)


def test_new_parent_in_history_holds_the_older_entry():
    """Between two entries with different parents tf2 returns the older one, not an interpolation."""
    b = BufferCore()
    b.set_transforms([item("a", "c", 1, 1.0), item("a", "c", 2, 2.0)])
    assert b.lookup("a", "c", int(1.5 * S))[1][0] == pytest.approx(1.5)
    b.set_transforms([item("b", "c", 3, 5.0), item("a", "b", 2, 1.0), item("a", "b", 4, 3.0)])
    assert b.lookup("a", "c", int(2.5 * S))[1][0] == pytest.approx(2.0)  # held at c's t=2 entry
    assert b.lookup("a", "c", 3 * S)[1][0] == pytest.approx(5.0 + 2.0)
    assert b.lookup("a", "c", int(1.5 * S))[1][0] == pytest.approx(1.5)


def test_clear_then_new_data():
    b = BufferCore()
    b.set_transforms([item("a", "b", 1, 1.0), item("a", "b", 2, 2.0)])
    b.lookup("a", "b", int(1.5 * S))
    b.lookup("a", "b", 0)
    b.clear()
    with pytest.raises(TransformException):
        b.lookup("a", "b", int(1.5 * S))
    b.set_transforms([item("a", "b", 5, 7.0), item("a", "b", 6, 9.0)])
    assert b.lookup("a", "b", int(5.5 * S))[1][0] == pytest.approx(8.0)
    assert b.lookup("a", "b", 0) == (6 * S, pytest.approx((9.0, 18.0, -9.0, 0, 0, 0, 1)))


def _answer(buf: BufferCore, target: str, source: str, t: int) -> tuple:
    try:
        stamp, tr = buf.lookup(target, source, t)
    except TransformException as exc:
        return (type(exc).__name__, str(exc))
    return ("ok", stamp, tr)


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_cached_answers_equal_a_fresh_buffer(seed):
    """Random inserts (in and out of order, repeats, statics, new parents) between lookups at
    latest, stored and interpolated times, each asked twice (the memo path): the live buffer,
    whose caches saw everything, answers exactly as a buffer rebuilt from the same inserts."""
    rnd = random.Random(seed)
    names = [f"f{i}" for i in range(8)]
    parents = {names[i]: names[rnd.randrange(i)] for i in range(1, len(names))}
    live = BufferCore(cache_time=3.0)
    log: list[tuple[list[tuple], bool]] = []
    for step in range(120):
        if rnd.random() < 0.6:
            child = rnd.choice(names[1:])
            if rnd.random() < 0.05:  # a new parent, from the frames above it (never a loop)
                parents[child] = names[rnd.randrange(names.index(child))]
            static = child in ("f3",)
            t = 0 if static else rnd.choice([rnd.randrange(1, 60) / 10, step / 20 + 1])
            turn = tilt_q if rnd.random() < 0.5 else yaw_q  # chains mix general and planar links
            batch = [item(parents[child], child, t, rnd.uniform(-2, 2), turn(rnd.uniform(-3, 3)))]
            live.set_transforms(batch, is_static=static)
            log.append((batch, static))
            continue
        fresh = BufferCore(cache_time=3.0)
        for batch, static in log:
            fresh.set_transforms(batch, is_static=static)
        target, source = rnd.sample(names, 2)
        for t in (0, rnd.randrange(1, 80) * S // 10, rnd.randrange(S, 8 * S)):
            want = _answer(fresh, target, source, t)
            for _ in range(2):
                got = _answer(live, target, source, t)
                assert got[:2] == want[:2], (step, target, source, t)
                if got[0] == "ok":
                    assert got[2] == pytest.approx(want[2], abs=1e-9)


def test_raw_batches_between_lookups_match_eager_insertion():
    """Batched raw messages land in frames whose records and memos are already filled."""
    from ninjemys.tf2.wire import decode_tf_message, encode_tf_message

    def message(k: int) -> bytes:
        t = 1.0 + 0.01 * k
        return encode_tf_message(
            [
                ("world" if i == 0 else f"f{i - 1}", f"f{i}", int(round(t * S)), t, i, 0.0, *tilt_q(t + i))
                for i in range(4)
            ]
        )

    lazy, eager = BufferCore(), BufferCore()
    for k in range(60):
        m = message(k)
        lazy.add_raw(m, "pub")
        eager.set_transforms(decode_tf_message(m), "pub")
        if k % 7 == 6:
            for t in (0, int((1.0 + 0.01 * k - 0.035) * S)):
                assert lazy.lookup("world", "f3", t) == eager.lookup("world", "f3", t)
                assert lazy.lookup("f1", "f3", t) == eager.lookup("f1", "f3", t)


@pytest.mark.parametrize("kinds", ["pppp", "pgpp", "ppgp", "gggg", "sppp", "pspg"])
def test_planar_links_compose_like_general_ones(kinds):
    """A chain mixing planar links (rotations about z only: complex-number arithmetic), general ones
    and static ones gives, at interpolated times, what composing each link's tf2 interpolation
    (lerp + tfm.slerp) gives, for both directions and through a common ancestor. The planar
    segments include a quaternion sign flip (the short way round) and a nearly constant rotation."""
    rnd = random.Random(kinds)
    b = BufferCore()
    chain = ["root", "l1", "l2", "l3", "l4"]
    pairs: dict[str, tuple[tuple, tuple]] = {}
    for k, kind in enumerate(kinds):
        parent, child = chain[k], chain[k + 1]
        if kind == "s":
            b.set_transforms([item(parent, child, 0, 0.3, yaw_q(0.4))], is_static=True)
            pairs[child] = (item(parent, child, 1, 0.3, yaw_q(0.4)), item(parent, child, 3, 0.3, yaw_q(0.4)))
            continue
        turn = yaw_q if kind == "p" else tilt_q
        a0 = rnd.uniform(-3, 3)
        a1 = a0 + (1e-7 if k == 2 else rnd.uniform(-2.5, 2.5))
        q1 = turn(a1)
        if k == 1:  # -q is the same rotation: the interpolation must take the short way round
            q1 = tuple(-v for v in q1)
        first, second = item(parent, child, 1, rnd.uniform(-2, 2), turn(a0)), item(parent, child, 3, 1.0, q1)
        b.set_transforms([first, second])
        pairs[child] = (first, second)
    b.set_transforms([item("root", "other", 1, 0.5, yaw_q(1.0)), item("root", "other", 3, -0.5, yaw_q(-2.0))])
    pairs["other"] = (item("root", "other", 1, 0.5, yaw_q(1.0)), item("root", "other", 3, -0.5, yaw_q(-2.0)))

    def to_root(frame: str, t: float) -> tuple:
        acc = tfm.IDENTITY
        while frame != "root":
            acc = tfm.compose(expected(*pairs[frame], t), acc)
            frame = pairs[frame][0][0]
        return acc

    for t in (1.0, 1.25, 2.0, 2.9, 3.0):
        ns = int(round(t * S))
        for target, source in (
            ("root", "l4"),
            ("l4", "root"),
            ("l1", "l4"),
            ("other", "l3"),
            ("l4", "other"),
        ):
            want = tfm.compose(tfm.inverse(to_root(target, t)), to_root(source, t))
            got = b.lookup(target, source, ns)[1]
            if (got[6] < 0) != (want[6] < 0):
                want = want[:3] + tuple(-v for v in want[3:])
            assert got == pytest.approx(want, abs=1e-9), (t, target, source)


def _planar_tree(b: BufferCore, stamps: list[float], static_x: float = 0.3) -> None:
    """root <- a <- b2 <- c (planar, sent together at each stamp), root <- d, and a static link c <- s."""
    for k, t in enumerate(stamps):
        b.set_transforms(
            [
                item("root", "a", t, 0.1 * k, yaw_q(0.3 * k)),
                item("a", "b2", t, -0.2 * k, yaw_q(-0.5 * k)),
                item("b2", "c", t, 0.05 * k, yaw_q(0.9 + 0.1 * k)),
                item("root", "d", t, 1.0 - 0.1 * k, yaw_q(2.0 - 0.2 * k)),
            ]
        )
    b.set_transforms([item("c", "s", 0, static_x, yaw_q(0.7))], is_static=True)


def _fresh_answer(log: list[tuple[list[tuple], bool]], target: str, source: str, t: int) -> tuple:
    fresh = BufferCore(cache_time=2.0)
    for batch, static in log:
        fresh.set_transforms(batch, is_static=static)
    return _answer(fresh, target, source, t)


def test_side_composites_follow_history_changes():
    """Many lookups at different times inside one segment (where a side's composite serves them) agree
    with a buffer that never cached anything, also after an out-of-order insert splits the segment,
    a repeated stamp replaces an end of it, a static link changes, and pruning removes it."""
    live = BufferCore(cache_time=2.0)
    log: list[tuple[list[tuple], bool]] = []

    class Recording:
        def set_transforms(self, batch: list[tuple], is_static: bool = False) -> None:
            live.set_transforms(batch, is_static=is_static)
            log.append((list(batch), is_static))

    _planar_tree(Recording(), [1.0, 1.5, 2.0])  # type: ignore[arg-type]

    def check() -> None:
        for t in (1.05, 1.1, 1.2, 1.3, 1.45, 1.55, 1.6, 1.7, 1.8, 1.9):
            ns = int(round(t * S))
            for target, source in (("d", "s"), ("s", "d"), ("root", "c"), ("a", "s"), ("d", "a")):
                want = _fresh_answer(log, target, source, ns)
                for _ in range(3):  # the second and later lookups in a segment use the composite
                    got = _answer(live, target, source, ns)
                    assert got[:2] == want[:2], (t, target, source)
                    if got[0] == "ok":
                        assert got[2] == pytest.approx(want[2], abs=1e-9), (t, target, source)

    check()
    # b2 alone moves on and prunes its 1.0..1.5 while c (the segment's lead for s's side) keeps it
    Recording().set_transforms([item("a", "b2", 3.5, 0.2, yaw_q(-1.0))])
    check()
    Recording().set_transforms([item("root", "a", 1.75, 5.0, yaw_q(-1.0))])  # splits a's 1.5..2.0
    check()
    Recording().set_transforms([item("b2", "c", 2.0, -3.0, yaw_q(2.5))])  # replaces an end
    check()
    Recording().set_transforms([item("c", "s", 0, -0.9, yaw_q(-0.2))], is_static=True)
    check()
    for t in (2.5, 3.0, 3.5, 4.0):  # 1.0..2.0 pruned away: those lookups now extrapolate
        batch = [
            item("root", "a", t, 0.3, yaw_q(t)),
            item("a", "b2", t, 0.2, yaw_q(-t)),
            item("b2", "c", t, 0.1, yaw_q(2 * t)),
            item("root", "d", t, 0.0, yaw_q(0.5 * t)),
        ]
        Recording().set_transforms(batch)
    check()


def _deep_tree(rnd: random.Random, n: int) -> dict[str, str]:
    """Mostly a chain, with side branches: lowest common ancestors at every depth."""
    names = [f"d{i}" for i in range(n)]
    return {names[i]: names[i - 1] if rnd.random() < 0.8 else names[rnd.randrange(i)] for i in range(1, n)}


@pytest.mark.parametrize("seed", [4, 5])
def test_deep_trees_answer_as_the_exact_walk(seed):
    """Frames 20-60 links deep (the lowest common ancestor is found by bisection on depth there):
    every lookup, at the latest time after each batch (the first lookup since an insertion takes the
    newest stamps along the sides) and at an interpolated time, equals tf2's exact walk."""
    rnd = random.Random(seed)
    parents = _deep_tree(rnd, 60)
    b = BufferCore()
    names = ["d0", *parents]
    for step in range(6):
        batch = [
            item(
                p,
                c,
                1 + step * 0.5 + (0.25 if c == "d7" and step == 5 else 0.0),
                rnd.uniform(-1, 1),
                yaw_q(rnd.uniform(-3, 3)),
            )
            for c, p in parents.items()
        ]
        b.set_transforms(batch)
        for _ in range(40):
            target, source = rnd.choice(names), rnd.choice(names)
            for t in (0, int((1 + step * 0.5 - rnd.uniform(0, 0.5 * min(step, 1))) * S)):
                got = _answer(b, target, source, t)
                tf, sf = b._frames[target], b._frames[source]
                err: list[str] = []
                if t == 0:
                    code, t_exact = b._common_time(tf, sf, err)
                    assert code == 0
                else:
                    t_exact = t
                if got[0] != "ok":
                    with pytest.raises(TransformException):
                        b._walk_transform(tf, sf, t_exact)
                    continue
                assert got[1] == t_exact, (target, source)
                assert got[2] == pytest.approx(b._walk_transform(tf, sf, t_exact), abs=1e-9)


def test_a_repeated_lookup_from_the_root_is_memoized(monkeypatch):
    """The top of a tree ("map") has no links: its transform to itself is memoized like any frame's,
    so asking again for a deep frame in the root at the same time composes no link (it walked all
    99 links on every call before)."""
    import ninjemys.tf2.core as core
    import ninjemys.tf2.fastpath as fastpath

    def fail(*_args):
        raise AssertionError("a memoized lookup composed links")

    b = BufferCore()
    for t in (1, 2):
        b.set_transforms([item(f"c{i - 1}", f"c{i}", t, 0.1 * i, yaw_q(0.01 * i * t)) for i in range(1, 100)])
    for target, source, t in (("c0", "c99", int(1.5 * S)), ("c99", "c0", 0)):
        first = b.lookup(target, source, t)
        b.lookup(target, source, t)  # the repeat fills the memos
        with monkeypatch.context() as patch:
            patch.setattr(fastpath, "_relative_at", fail)
            patch.setattr(core.Frame, "at", fail)
            for _ in range(3):
                again = b.lookup(target, source, t)
                assert again[0] == first[0] and again[1] == pytest.approx(first[1], abs=1e-9)


@pytest.mark.parametrize("cache_time", [2, 9, 17, 33, 50])
def test_history_is_exactly_cache_time_long(cache_time):
    """tf2 prunes on every insertion: an entry older than the newest minus cache_time is gone. Ours
    trims its lists in steps but hides those entries from every lookup path (single link, memo,
    per-link chain, side composite), with tf2's error text (ROS 1's tf test_cache_time)."""
    b = BufferCore(cache_time=float(cache_time))
    for ti in range(101):
        b.set_transforms([item("p", "c", ti, 1.0, yaw_q(0.1 * ti)), item("c", "d", ti, 2.0, yaw_q(0.2 * ti))])
    first = 100 - cache_time
    for ti in range(1, 100):
        for target, source in (("p", "c"), ("p", "d"), ("d", "p")):
            for t in (ti * S, ti * S + S // 2):  # a stored stamp, and between two
                for _ in range(2):  # the second lookup in a segment uses the side composite
                    if t >= first * S:
                        b.lookup(target, source, t)
                    else:
                        with pytest.raises(
                            TransformException, match=f"earliest data is at time {first}.000000000"
                        ):
                            b.lookup(target, source, t)
    assert b._frames["c"].oldest() == first * S


def test_a_composite_made_before_its_segment_aged_out_is_not_used():
    """A side composite built while its segment was in the history stops answering once newer data
    moves the segment past cache_time."""
    b = BufferCore(cache_time=16.0)  # the lists are trimmed once 1 s longer than that
    for ti in range(1, 4):
        b.set_transforms([item("p", "c", ti, 1.0, yaw_q(0.1 * ti)), item("c", "d", ti, 2.0, yaw_q(0.2 * ti))])
    for r in (0.3, 0.5, 0.7):  # different times in one segment: the 1..2 segment's composite
        b.lookup("p", "d", int((1 + r) * S))
    assert any(isinstance(c, tuple) and len(c) > 1 for c in b._frames["d"].sides[b._frames["p"]][0].values())
    b.set_transforms([item("p", "c", 17.5, 1.0, yaw_q(0.6)), item("c", "d", 17.5, 2.0, yaw_q(1.3))])
    assert b._frames["d"].stamps[0] == S  # still stored, but older than 17.5 - 16: pruned for tf2
    with pytest.raises(TransformException, match="earliest data is at time 2.000000000"):
        b.lookup("p", "d", int(1.4 * S))

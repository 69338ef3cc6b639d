"""The tf2 buffer core alone: caches, interpolation, latest common time, tf2's errors, bad input, waits."""

from __future__ import annotations

import logging
import math
import threading
import time

import pytest

from ninjemys.tf2.core import BufferCore
from ninjemys.tf2.errors import (
    ConnectivityException,
    ExtrapolationException,
    InvalidArgumentException,
    LookupException,
)

S = 1_000_000_000
IDQ = (0.0, 0.0, 0.0, 1.0)


def item(parent, child, t, x=0.0, y=0.0, z=0.0, q=IDQ):
    return (parent, child, int(round(t * S)), x, y, z, *q)


def yaw_q(yaw):
    return (0.0, 0.0, math.sin(yaw / 2), math.cos(yaw / 2))


@pytest.fixture
def buf() -> BufferCore:
    b = BufferCore(10.0)
    b.set_transforms([item("map", "odom", 10, 1), item("map", "odom", 12, 2)], "me")
    b.set_transforms([item("odom", "base", 11, 0, 1), item("odom", "base", 13, 0, 2)], "me")
    b.set_transforms([item("base", "laser", 0, 0, 0, 1)], "st", is_static=True)
    b.set_transforms([item("other", "x", 5, 0, 0, 1)], "o")
    return b


def test_latest_common_time_and_static(buf):
    stamp, t = buf.lookup("map", "laser", 0)
    assert stamp == 12 * S  # map->odom ends at 12, odom->base at 13: the common latest is 12
    assert t == pytest.approx((2.0, 1.5, 1.0, 0, 0, 0, 1))


def test_interpolation_lerps_translation(buf):
    stamp, t = buf.lookup("map", "laser", int(11.5 * S))
    assert stamp == int(11.5 * S)
    assert t[:3] == pytest.approx((1.75, 1.25, 1.0))


def test_slerp_rotation():
    b = BufferCore()
    b.set_transforms([item("a", "b", 1, q=yaw_q(0.0)), item("a", "b", 2, q=yaw_q(1.0))])
    _, t = b.lookup("a", "b", int(1.25 * S))
    assert t[3:] == pytest.approx(yaw_q(0.25))
    # the short way round: -q is the same rotation as q
    b.set_transforms([item("a", "c", 1, q=yaw_q(3.0)), item("a", "c", 2, q=tuple(-v for v in yaw_q(-3.0)))])
    _, t = b.lookup("a", "c", int(1.5 * S))
    angle = 2 * math.atan2(t[5], t[6])
    assert math.remainder(angle - math.pi, 2 * math.pi) == pytest.approx(0.0, abs=1e-9)


def test_extrapolation_says_future_and_past_and_how_much(buf):
    with pytest.raises(ExtrapolationException) as e:
        buf.lookup("map", "laser", 20 * S)
    assert str(e.value) == (
        "Lookup would require extrapolation 7.000000000s into the future.  Requested time 20.000000000 but the "
        "latest data is at time 13.000000000, when looking up transform from frame [laser] to frame [map]"
    )
    with pytest.raises(ExtrapolationException) as e:
        buf.lookup("map", "laser", 1 * S)
    assert "10.000000000s into the past" in str(e.value)
    assert "earliest data is at time 11.000000000" in str(e.value)


def test_tf2_lookup_errors(buf):
    with pytest.raises(
        LookupException, match='"nope" passed to lookupTransform argument source_frame does not'
    ):
        buf.lookup("map", "nope", 0)
    with pytest.raises(ConnectivityException, match="Could not find a connection between 'map' and 'x'"):
        buf.lookup("map", "x", 0)
    with pytest.raises(InvalidArgumentException, match="frame_ids cannot be empty"):
        buf.lookup("", "map", 0)
    with pytest.raises(InvalidArgumentException, match="cannot start with a '/'"):
        buf.lookup("map", "/odom", 0)
    assert buf.can_transform("map", "nope", 0) == (False, "canTransform: source_frame nope does not exist.")
    ok, why = buf.can_transform("map", "x", 20 * S)
    assert not ok and "only time 5.000000000 is in the buffer" in why
    assert buf.lookup("nope", "nope", 3 * S) == (3 * S, (0, 0, 0, 0, 0, 0, 1))


def test_full_lookup_and_chain(buf):
    stamp, t = buf.lookup_full("map", 11 * S, "laser", 12 * S, "odom")
    assert stamp == 11 * S
    assert t[:3] == pytest.approx((1.5, 1.5, 1.0))
    assert buf.chain("map", 0, "laser", 0, "odom") == ["laser", "base", "odom", "map"]


def test_lookup_below_a_stale_parent_uses_the_walk():
    """odom->base is fresher than map->odom: lookups inside odom must not need map->odom's data."""
    b = BufferCore()
    b.set_transforms([item("map", "odom", 1, 1)])
    b.set_transforms([item("odom", "base", 5, 2), item("odom", "base", 6, 3)])
    for _ in range(3):  # a one-off time, then the same time again (the memo path), then again
        assert b.lookup("odom", "base", int(5.5 * S))[1][0] == pytest.approx(2.5)
        assert b.lookup("odom", "base", 0) == (6 * S, (3.0, 0, 0, 0, 0, 0, 1))
    with pytest.raises(ExtrapolationException):
        b.lookup("map", "base", int(5.5 * S))


def test_yaml_and_string_views(buf):
    y = buf.all_frames_as_yaml()
    assert y.startswith("odom: \n  parent: 'map'\n  broadcaster: 'me'\n  rate: 1.000\n")
    assert "laser: \n  parent: 'base'\n  broadcaster: 'st'\n  rate: 10000.000\n" in y
    assert buf.all_frames_as_string().splitlines()[0] == "Frame odom exists with parent map."
    assert BufferCore().all_frames_as_yaml() == "{}"
    assert buf.frame_names() == ["odom", "map", "base", "laser", "x", "other"]
    assert buf.all_frames_as_dot().startswith('digraph G {\n"map" -> "odom"[label="Broadcaster: me\\n')


def test_cache_time_prunes_history():
    b = BufferCore(cache_time=2.0)
    b.set_transforms([item("a", "b", t) for t in range(10)])
    ok, why = b.can_transform("a", "b", 6 * S)
    assert not ok and "into the past" in why
    assert b.can_transform("a", "b", 7 * S) == (True, "")


def test_repeated_stamp_updates_quietly(caplog):
    b = BufferCore()
    with caplog.at_level(logging.DEBUG, logger="ninjemys.tf2"):
        for i in range(50):
            b.set_transforms([item("a", "b", 1, x=float(i))], "spammy")
    assert b.lookup("a", "b", 1 * S)[1][0] == 49.0  # the newest data won
    assert not [r for r in caplog.records if r.levelno >= logging.INFO]
    assert len([r for r in caplog.records if "TF_REPEATED_DATA" in r.message]) <= 1


@pytest.mark.parametrize(
    ("bad", "expected"),
    [
        (item("", "a", 1), 'TF_NO_FRAME_ID: Ignoring transform with child_frame_id "a"'),
        (item("a", "", 1), 'TF_NO_CHILD_FRAME_ID: Ignoring transform from authority "bad" (frame_id "a")'),
        (item("a", "a", 1), 'TF_SELF_TRANSFORM: Ignoring transform from authority "bad" with frame_id and'),
        (
            item("a", "b", 1, x=float("nan")),
            'TF_NAN_INPUT: Ignoring transform for child_frame_id "b" (parent "a")',
        ),
        (item("a", "b", 1, q=(0, 0, 0, float("nan"))), "TF_NAN_INPUT"),
        (
            item("a", "b", 1, q=(0, 0, 0, 2)),
            'TF_DENORMALIZED_QUATERNION: Ignoring transform for child_frame_id "b"',
        ),
        (
            item("laser", "map", 1),
            'TF_LOOP: Ignoring transform for child_frame_id "map" with frame_id "laser"',
        ),
    ],
)
def test_bad_input_one_line_and_keeps_serving(buf, bad, expected):
    lines: list[str] = []
    buf._report = lines.append
    assert buf.set_transforms([bad, item("map", "odom", 12.5, 3)], "bad") == 1
    assert len(lines) == 1 and lines[0].startswith(expected), lines
    assert buf.lookup("map", "laser", 0)[0] == int(12.5 * S)


def test_loop_message_names_the_cycle(buf):
    lines: list[str] = []
    buf._report = lines.append
    buf.set_transforms([item("laser", "map", 1)], "bad")
    assert lines[0].endswith("it would close a loop: map -> odom -> base -> laser -> map")


def test_can_transform_wait_is_woken_by_data():
    b = BufferCore()
    b.set_transforms([item("a", "b", 1)])

    def later():
        time.sleep(0.2)
        b.set_transforms([item("b", "c", 1)])

    threading.Thread(target=later).start()
    start = time.monotonic()
    ok, _ = b.wait_for_transform(lambda: b.can_transform("a", "c", 0), 5.0)
    assert ok and time.monotonic() - start < 2.0
    start = time.monotonic()
    ok, why = b.wait_for_transform(lambda: b.can_transform("a", "zz", 0), 0.2)
    assert not ok and why == "canTransform: source_frame zz does not exist."
    assert 0.15 < time.monotonic() - start < 2.0


def test_clear_keeps_static(buf):
    buf.clear()
    assert buf.can_transform("base", "laser", 5 * S) == (True, "")
    assert not buf.can_transform("map", "odom", 11 * S)[0]


def test_reparenting_over_time():
    b = BufferCore()
    b.set_transforms([item("a", "c", 1, x=1.0), item("a", "c", 2, x=2.0)])
    b.set_transforms([item("b", "c", 3, x=5.0), item("a", "b", 3, x=10.0)])
    assert b.lookup("a", "c", int(1.5 * S))[1][0] == pytest.approx(1.5)
    assert b.lookup("a", "c", 3 * S)[1][0] == pytest.approx(15.0)


def _raw_messages(count, start=1, step=0.01, frames=5, bad_at=None, reorder=False):
    from ninjemys.tf2.wire import encode_tf_message

    out = []
    for k in range(count):
        t = start + k * step
        items = [
            (
                "world" if i == 0 else f"f{i - 1}",
                f"f{i}",
                int(round(t * S)),
                math.cos(t + i),
                math.sin(t),
                0.1 * i,
                *yaw_q(t + i),
            )
            for i in range(frames)
        ]
        if k == bad_at:
            items[2] = items[2][:3] + (float("nan"),) + items[2][4:]
        out.append(encode_tf_message(items))
    if reorder:
        out[3], out[4] = out[4], out[3]
    return out


@pytest.mark.parametrize("case", ["plain", "bad-in-run", "reordered", "repeated"])
def test_raw_batches_match_eager_insertion(case):
    """add_raw (batched numpy decoding) and set_transforms (per transform) give the same buffer."""
    from ninjemys.tf2.wire import decode_tf_message

    msgs = _raw_messages(40, bad_at=7 if case == "bad-in-run" else None, reorder=case == "reordered")
    if case == "repeated":
        msgs = msgs[:10] + msgs[5:10] + msgs[10:]
    lazy, eager = BufferCore(), BufferCore()
    lazy_lines: list[str] = []
    eager_lines: list[str] = []
    lazy._report, eager._report = lazy_lines.append, eager_lines.append
    for m in msgs:
        lazy.add_raw(m, "pub")
        eager.set_transforms(decode_tf_message(m), "pub")
    for t in (0, S + 5 * S // 100, S + 123 * S // 10_000, S + 39 * S // 100):
        for target, source in (("world", "f4"), ("f2", "f4"), ("f4", "f1")):
            assert lazy.lookup(target, source, t) == eager.lookup(target, source, t)
    assert lazy.all_frames_as_yaml() == eager.all_frames_as_yaml()
    assert lazy_lines == eager_lines
    if case == "bad-in-run":
        assert len(lazy_lines) == 1 and lazy_lines[0].startswith(
            'TF_NAN_INPUT: Ignoring transform for child_frame_id "f2"'
        )


def test_raw_queue_is_bounded_and_wakes_waiters():
    from ninjemys.tf2 import core

    b = BufferCore()
    for m in _raw_messages(core.PENDING_MAX + 3):
        b.add_raw(m, "pub")
    assert len(b._pending) == 3  # the listener's thread decoded the first batch itself
    msgs = _raw_messages(1, start=5)

    def later():
        time.sleep(0.2)
        b.add_raw(msgs[0], "pub")

    threading.Thread(target=later).start()
    ok, _ = b.wait_for_transform(lambda: b.can_transform("world", "f4", 5 * S), 5.0)
    assert ok


def test_change_listeners_hear_new_data():
    b = BufferCore()
    heard: list[bool] = []
    b.add_change_listener(lambda: heard.append(b.can_transform("world", "f4", 0)[0]))
    b.set_transforms([item("a", "b", 1)])
    for m in _raw_messages(1):
        b.add_raw(m, "pub")
    assert heard == [False, True]


def test_listener_clears_on_a_jump_back_in_time():
    from ninjemys.node.subscriber import RawMessage
    from ninjemys.tf2.node import TransformListener

    class FakeNode:
        def subscriber(self, topic, msg_class, callback, **kwargs):
            class Sub:
                def unregister(self):
                    pass

            return Sub()

    clock = [100.0]
    lines: list[str] = []
    b = BufferCore(report=lines.append)
    listener = TransformListener(FakeNode(), b, now=lambda: clock[0], report=lines.append)
    header = {"callerid": "/pub", "md5sum": "94810edda583a504dfda3829e70d7eec"}
    listener._on_tf_static(RawMessage(_raw_messages(1, frames=2)[0], header))
    listener._on_tf(RawMessage(_raw_messages(1, start=3, frames=3)[0], header))
    assert b.can_transform("world", "f2", 0)[0]
    clock[0] = 50.0  # a bag loop or a simulator reset
    listener._on_tf(RawMessage(_raw_messages(1, start=1, frames=1)[0], header))
    assert lines == ["Detected jump back in time of 50.000000s. Clearing TF buffer."]
    assert not b.can_transform("world", "f2", 0)[0]  # the old dynamic data is gone
    assert b.can_transform("world", "f1", 0)[0]
    listener._on_tf(RawMessage(b"\x05\x00", {"callerid": "/odd", "md5sum": "0123"}))
    assert lines[-1] == "/tf: /odd publishes type None (md5 0123), not tf2_msgs/TFMessage"
    listener._on_tf(RawMessage(b"\x05\x00\x00\x00", header))  # five transforms announced, none there
    assert b.can_transform("world", "f1", 0)[0]
    assert lines[-1].startswith("/tf: dropped a message from /pub: tf2_msgs/TFMessage: cannot decode 4 bytes")

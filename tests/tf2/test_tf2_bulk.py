"""ninjemys.tf2.bulk: many TFMessages of one layout read with numpy give exactly what the per-message
decoder gives, whatever the byte alignment of their numbers, and refuse messages whose ids differ."""

from __future__ import annotations

import random

import pytest

from ninjemys.tf2.bulk import Layout, valid
from ninjemys.tf2.wire import decode_tf_message, encode_tf_message

NS = 1_000_000_000


def _message(rng: random.Random, names: list[tuple[str, str]], stamp: int) -> bytes:
    items = []
    for parent, child in names:
        q = [rng.uniform(-1, 1) for _ in range(4)]
        norm = sum(c * c for c in q) ** 0.5
        items.append(
            (parent, child, stamp + rng.randrange(NS), *(rng.uniform(-50, 50) for _ in range(3)))
            + tuple(c / norm for c in q)
        )
    return encode_tf_message(items)


@pytest.mark.parametrize("k", [1, 2, 7, 24, 25, 50])  # one message to many
def test_bulk_read_equals_the_decoder_at_every_alignment(k: int) -> None:
    rng = random.Random(k)
    # frame ids of lengths 1..9 put the numbers of successive transforms at every offset modulo 8
    names = [("p" * (1 + i % 9), "c" * (1 + (i * 5) % 9) + str(i)) for i in range(23)]
    messages = [_message(rng, names, (1_700_000_000 + j) * NS) for j in range(k)]
    layout = Layout(messages[0])
    assert all(layout.matches(m) for m in messages)
    got = layout.read(messages)
    assert got is not None
    stamps, values = got
    assert stamps.shape == (k, len(names)) and values.shape == (k, len(names), 7)
    for row, m in enumerate(messages):
        decoded = decode_tf_message(m)
        assert stamps[row].tolist() == [it[2] for it in decoded]
        assert values[row].tolist() == [list(it[3:]) for it in decoded]  # bit for bit
    assert valid(values, 1e-5)


def test_bulk_read_refuses_other_ids_and_bad_numbers() -> None:
    rng = random.Random(3)
    names = [("map", "odom"), ("odom", "base_link"), ("base_link", "laser")]
    messages = [_message(rng, names, (10 + j) * NS) for j in range(4)]
    layout = Layout(messages[0])
    other = messages[2].replace(b"laser", b"lidar")
    assert layout.matches(other)  # same length and count: only the full check tells
    assert layout.read([*messages[:2], other, messages[3]]) is None
    stamps, values = layout.read(messages)  # type: ignore[misc]
    bad = values.copy()
    bad[1, 2, 6] = float("nan")
    assert not valid(bad, 1e-5)
    bad = values.copy()
    bad[3, 0, 3:] *= 1.01  # a quaternion 1 % too long
    assert not valid(bad, 1e-5)
    assert valid(values, 1e-5)
    assert stamps[:, 0].tolist() == [it[2] for it in (decode_tf_message(m)[0] for m in messages)]

"""The buffer core's two lookup paths against each other, in process: the fast path (memos, segment
records, planar composites) and the reference path (tf2's walk alone, ``BufferCore(fast=False)``) must
give the same answers, stamps and error texts on the same random operations (the differential peer's
script), and the module switch must pick the path of new buffers."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

from ninjemys.tf2 import core
from ninjemys.tf2.core import BufferCore

sys.path.insert(0, str(Path(__file__).parent))
import tf_diff_peer  # noqa: E402


def _run(seed: int, fast: bool, monkeypatch: pytest.MonkeyPatch) -> list:
    with monkeypatch.context() as patch:
        patch.setattr(core, "FAST", fast)
        return tf_diff_peer.run(seed)


@pytest.mark.parametrize("seed", [11, 12, 13, 14])
def test_fast_and_reference_paths_agree(seed, monkeypatch):
    fast = _run(seed, True, monkeypatch)
    ref = _run(seed, False, monkeypatch)
    assert len(fast) == len(ref)
    oks = 0
    for a, b in zip(fast, ref, strict=True):
        if a[0] == "ok" and b[0] == "ok":
            oks += 1
            assert a[1:3] == b[1:3] and a[3][:2] == b[3][:2], (seed, a, b)
            assert a[3][2:] == pytest.approx(b[3][2:], abs=1e-9), (seed, a, b)
        else:
            assert a == b, seed
    assert oks > 50  # the script looks up enough pairs that work


def test_the_switch_picks_the_path(monkeypatch):
    """``fast=False`` (or FAST off) never enters the fast path's lookup; the default does."""
    calls = []
    real = core.BufferCore._lookup

    def spy(self, *args):
        calls.append(args)
        return real(self, *args)

    monkeypatch.setattr(core.BufferCore, "_lookup", spy)
    items = [("map", "odom", 10**9, 1, 0, 0, 0, 0, 0, 1), ("odom", "base", 10**9, 0, 1, 0, 0, 0, 0, 1)]
    for buf, used in ((BufferCore(fast=False), False), (BufferCore(), True)):
        buf.set_transforms(items)
        assert buf.lookup("map", "base", 0) == (10**9, (1.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0))
        assert buf.can_transform("base", "map", 10**9) == (True, "")
        assert bool(calls) is used
    monkeypatch.setattr(core, "FAST", False)
    assert BufferCore().fast is False
    assert BufferCore(fast=True).fast is True

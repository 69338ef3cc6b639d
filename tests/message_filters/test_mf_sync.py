"""message_filters' synchronizers and Cache, checked against Debian's python3-message-filters on the same input."""

from __future__ import annotations

import json
import random
import subprocess
from pathlib import Path

import pytest

from ninjemys.message_filters import ApproximateTimeSynchronizer, Cache, Chain, SimpleFilter, TimeSynchronizer
from ninjemys.rostime import Time
from ninjemys.testing import ROS1_PYTHON, ros1_env

ORACLE = Path(__file__).with_name("mf_oracle.py")


class Header:
    def __init__(self, stamp: Time) -> None:
        self.stamp = stamp


class Msg:
    def __init__(self, secs: int, nsecs: int) -> None:
        self.header = Header(Time(secs, nsecs))


class Headerless:
    pass


def run_ours(spec: dict) -> list:
    sources = [SimpleFilter() for _ in range(spec["inputs"])]
    if spec["kind"] == "exact":
        sync = TimeSynchronizer(sources, spec["queue_size"])
    else:
        sync = ApproximateTimeSynchronizer(sources, spec["queue_size"], spec["slop"])
    out: list = []
    sync.registerCallback(
        lambda *msgs: out.append([[m.header.stamp.secs, m.header.stamp.nsecs] for m in msgs])
    )
    for index, secs, nsecs in spec["events"]:
        sources[index].signalMessage(Msg(secs, nsecs))
    return out


def events(seed: int, inputs: int, count: int, exact: bool) -> list[list[int]]:
    """Sensor-like streams: ~10 Hz per input with jitter, drops, and some out-of-order arrivals."""
    rng = random.Random(seed)
    out = []
    for k in range(count):
        base = 1_000_000_000 + k * 100_000_000
        for i in range(inputs):
            if rng.random() < 0.15:
                continue  # dropped
            jitter = 0 if exact else rng.randint(-40_000_000, 40_000_000)
            t = base + jitter + (0 if exact or rng.random() > 0.05 else 3 * 100_000_000)
            out.append([i, *divmod(t, 1_000_000_000)])
    # shuffle within small windows: arrival order differs from stamp order
    for start in range(0, len(out) - 3, 3):
        window = out[start : start + 3]
        rng.shuffle(window)
        out[start : start + 3] = window
    return out


def test_exact_sync_basic() -> None:
    a, b = SimpleFilter(), SimpleFilter()
    sync = TimeSynchronizer([a, b], 10)
    got: list = []
    sync.registerCallback(lambda x, y, tag: got.append((x, y, tag)), "tag")
    m1, m2, m3 = Msg(1, 0), Msg(1, 0), Msg(2, 0)
    a.signalMessage(m1)
    a.signalMessage(m3)
    assert got == []
    b.signalMessage(m2)
    assert got == [(m1, m2, "tag")]


def test_approx_headerless_and_warning(caplog: pytest.LogCaptureFixture) -> None:
    a, b = SimpleFilter(), SimpleFilter()
    strict = ApproximateTimeSynchronizer([a, b], 10, 0.1)
    got: list = []
    strict.registerCallback(lambda *m: got.append(m))
    a.signalMessage(Headerless())
    assert got == [] and "allow_headerless" in caplog.text
    a2, b2 = SimpleFilter(), SimpleFilter()
    lenient = ApproximateTimeSynchronizer([a2, b2], 10, 1.0, allow_headerless=True)
    lenient.registerCallback(lambda *m: got.append(m))
    x, y = Headerless(), Headerless()
    a2.signalMessage(x)
    b2.signalMessage(y)
    assert got == [(x, y)]


def test_cache_queries() -> None:
    src = SimpleFilter()
    cache = Cache(src, cache_size=3)
    seen: list = []
    cache.registerCallback(seen.append)
    msgs = [Msg(s, 0) for s in (1, 2, 3, 4)]
    for m in msgs:
        src.signalMessage(m)
    assert seen == msgs and cache.cache_msgs == msgs[1:]
    assert cache.getInterval(Time(2), Time(3)) == msgs[1:3]
    assert cache.getElemAfterTime(Time(2, 5)) is msgs[2]
    assert cache.getElemBeforeTime(Time(2, 5)) is msgs[1]
    assert cache.getElemBeforeTime(Time(1)) is None
    assert cache.getLatestTime() == Time(4) and cache.getOldestTime() == Time(2)
    assert cache.getLast() is msgs[3] and cache.getLastestTime() == Time(4)


def test_chain_passes_through_stages() -> None:
    src = SimpleFilter()
    chain = Chain(src)
    first = chain.addFilter(Cache(SimpleFilter(), 5))
    chain.addFilter(Cache(SimpleFilter(), 2))
    out: list = []
    chain.registerCallback(out.append)
    msgs = [Msg(s, 0) for s in (1, 2, 3)]
    for m in msgs:
        src.signalMessage(m)
    assert out == msgs and chain.getFilter(0) is first and len(chain.getFilter(1).cache_msgs) == 2


@pytest.mark.ros1
@pytest.mark.parametrize(
    ("kind", "inputs", "queue_size", "slop", "seed"),
    [
        ("exact", 2, 5, 0.0, 1),
        ("exact", 3, 3, 0.0, 2),
        ("approx", 2, 10, 0.05, 3),
        ("approx", 3, 10, 0.05, 4),
        ("approx", 3, 4, 0.1, 5),
        ("approx", 4, 6, 0.03, 6),
    ],
)
def test_same_output_as_ros1(kind: str, inputs: int, queue_size: int, slop: float, seed: int) -> None:
    spec = {
        "kind": kind,
        "inputs": inputs,
        "queue_size": queue_size,
        "slop": slop,
        "events": events(seed, inputs, 300, kind == "exact"),
    }
    theirs = subprocess.run(
        [ROS1_PYTHON, str(ORACLE)],
        input=json.dumps(spec),
        capture_output=True,
        text=True,
        env=ros1_env("http://localhost:1/"),
        timeout=60,
    )
    assert theirs.returncode == 0, theirs.stderr
    expected = json.loads(theirs.stdout)
    assert len(expected) > 10
    assert run_ours(spec) == expected

"""ROS clock: wall vs simulated time, /clock handling, prompt wake-ups, backwards jumps."""

from __future__ import annotations

import threading
import time
from types import SimpleNamespace

from ninjemys import rostime
from ninjemys.node.clock import Clock, Wake, for_node
from ninjemys.testing import FakeClock


def _in_thread(fn):
    box: dict = {}
    t = threading.Thread(target=lambda: box.setdefault("r", fn()), daemon=True)
    t.start()
    return t, box


def test_wall_clock_reads_time() -> None:
    clock = Clock()
    assert clock.is_wallclock
    assert abs(clock.now() - time.time()) < 1.0
    assert abs(clock.now_ns() / 1e9 - time.time()) < 1.0


def test_sim_time_is_zero_until_first_clock_message() -> None:
    clock = Clock(sim=True)
    assert clock.now() == 0.0
    clock.on_clock_message(SimpleNamespace(clock=SimpleNamespace(secs=12, nsecs=500_000_000)))
    assert clock.now() == 12.5
    assert clock.now_pair() == (12, 500_000_000)


def test_sim_waiter_wakes_when_time_reaches_target() -> None:
    clock = FakeClock(10.0)
    t, box = _in_thread(lambda: clock.wait_until(11.0))
    clock.advance(0.5)
    t.join(0.2)
    assert t.is_alive(), "woke before time reached the target"
    clock.advance(0.6)
    t.join(2)
    assert box["r"] is Wake.REACHED


def test_shutdown_wakes_every_waiter_promptly() -> None:
    clock = Clock()
    threads = [_in_thread(lambda: clock.wait_for(60.0)) for _ in range(3)]
    time.sleep(0.05)
    start = time.monotonic()
    clock.shutdown()
    for t, _ in threads:
        t.join(2)
    assert time.monotonic() - start < 1.0
    assert all(box["r"] is Wake.SHUTDOWN for _, box in threads)
    assert clock.wait_for(1.0) is Wake.SHUTDOWN


def test_backwards_jump_is_reported() -> None:
    clock = FakeClock(100.0)
    t, box = _in_thread(lambda: clock.wait_until(200.0))
    time.sleep(0.05)
    clock.set(5.0)
    t.join(2)
    assert box["r"] is Wake.MOVED_BACKWARDS
    assert clock.epoch == 1


def test_cancel_predicate_with_wake() -> None:
    clock = FakeClock()
    flag = threading.Event()
    t, box = _in_thread(lambda: clock.wait_until(5.0, flag.is_set))
    flag.set()
    clock.wake()
    t.join(2)
    assert box["r"] is Wake.CANCELLED


def test_install_hooks_rostime_now() -> None:
    clock = FakeClock(42.25)
    try:
        clock.install()
        assert rostime.Time.now() == rostime.Time(42, 250_000_000)
        clock.advance(1.0)
        assert rostime.Time.now().to_sec() == 43.25
    finally:
        rostime.set_clock(None)
    assert rostime.Time.now().to_sec() > 1_600_000_000


class _FakeNode:
    def __init__(self, sim: object) -> None:
        self.sim = sim
        self.subscribed: list = []

    def get_param(self, key: str, default: object = None) -> object:
        assert key == "/use_sim_time"
        if isinstance(self.sim, Exception):
            raise self.sim
        return self.sim

    def subscriber(self, topic, cls, cb, queue_size=None):
        self.subscribed.append((topic, cls, queue_size))
        return SimpleNamespace(unregister=lambda: None)


def test_for_node_follows_use_sim_time() -> None:
    wall = for_node(_FakeNode(False))
    assert wall.is_wallclock
    sim_node = _FakeNode(True)
    sim = for_node(sim_node)
    assert sim.is_sim and sim.now() == 0.0
    ((topic, cls, qs),) = sim_node.subscribed
    assert topic == "/clock" and cls._type == "rosgraph_msgs/Clock" and qs == 1
    assert for_node(_FakeNode(OSError("no master"))).is_wallclock


def test_switch_to_sim_wakes_wall_waiters_to_reanchor() -> None:
    clock = Clock()
    t, box = _in_thread(lambda: clock.wait_for(60.0))
    time.sleep(0.05)
    clock.switch_to_sim()
    t.join(2)
    assert box["r"] is Wake.MOVED_BACKWARDS
    assert clock.is_sim and clock.now() == 0.0
    clock.switch_to_sim()  # idempotent
    assert clock.epoch == 1

"""sleep, Rate and Timer over wall and simulated clocks (FakeClock drives simulated time)."""

from __future__ import annotations

import threading
import time

import pytest

from ninjemys.errors import ShutdownError
from ninjemys.node.clock import Clock
from ninjemys.node.timers import Rate, TimeMovedBackwardsError, Timer, TimerEvent, sleep
from ninjemys.testing import FakeClock


def _run(fn):
    box: dict = {}

    def target() -> None:
        try:
            box["r"] = fn()
        except BaseException as exc:  # noqa: BLE001 - the test inspects it
            box["e"] = exc

    t = threading.Thread(target=target, daemon=True)
    t.start()
    return t, box


def _wait_blocked(t: threading.Thread) -> None:
    time.sleep(0.05)
    assert t.is_alive()


def test_wall_sleep_sleeps() -> None:
    clock = Clock()
    start = time.monotonic()
    sleep(clock, 0.05)
    assert time.monotonic() - start >= 0.045
    sleep(clock, 0)
    sleep(clock, -1)


def test_sleep_raises_on_shutdown_promptly() -> None:
    clock = Clock()
    t, box = _run(lambda: sleep(clock, 30))
    _wait_blocked(t)
    clock.shutdown()
    t.join(1)
    assert isinstance(box["e"], ShutdownError)
    with pytest.raises(ShutdownError):
        sleep(clock, 0.1)


def test_sim_sleep_follows_sim_time() -> None:
    clock = FakeClock(1.0)
    t, box = _run(lambda: sleep(clock, 2.0))
    _wait_blocked(t)
    clock.advance(1.0)
    _wait_blocked(t)
    clock.advance(1.0)
    t.join(2)
    assert not t.is_alive() and "e" not in box


def test_sim_sleep_raises_when_time_moves_backwards() -> None:
    clock = FakeClock(50.0)
    t, box = _run(lambda: sleep(clock, 2.0))
    _wait_blocked(t)
    clock.set(1.0)
    t.join(2)
    assert isinstance(box["e"], TimeMovedBackwardsError)
    assert "moved backwards" in str(box["e"])


def test_rate_keeps_period_in_sim_time() -> None:
    clock = FakeClock(0.0)
    rate = Rate(10, clock)
    t, _ = _run(rate.sleep)
    _wait_blocked(t)
    clock.advance(0.1)
    t.join(2)
    assert rate.last_time == pytest.approx(0.1)
    assert rate.remaining() == pytest.approx(0.1)


def test_rate_resets_on_backwards_jump_instead_of_dying() -> None:
    clock = FakeClock(100.0)
    rate = Rate(10, clock)
    t, box = _run(rate.sleep)
    _wait_blocked(t)
    clock.set(3.0)
    t.join(2)
    assert "e" not in box
    assert rate.last_time == pytest.approx(3.0)
    # and it keeps working from the new time
    t, box = _run(rate.sleep)
    _wait_blocked(t)
    clock.advance(0.1)
    t.join(2)
    assert "e" not in box and not t.is_alive()


def test_rate_reset_false_keeps_rospy_behaviour() -> None:
    clock = FakeClock(100.0)
    rate = Rate(10, clock, reset=False)
    t, box = _run(rate.sleep)
    _wait_blocked(t)
    clock.set(3.0)
    t.join(2)
    assert isinstance(box["e"], TimeMovedBackwardsError)


def test_rate_wall_clock_frequency_and_shutdown() -> None:
    clock = Clock()
    rate = Rate(50, clock)
    start = time.monotonic()
    for _ in range(5):
        rate.sleep()
    assert time.monotonic() - start >= 0.08
    t, box = _run(lambda: Rate(0.01, clock).sleep())
    _wait_blocked(t)
    clock.shutdown()
    t.join(1)
    assert isinstance(box["e"], ShutdownError)


def test_rate_rejects_bad_frequency() -> None:
    with pytest.raises(ValueError):
        Rate(0, Clock())


def test_timer_fires_with_events_in_sim_time() -> None:
    clock = FakeClock(10.0)
    events: list[TimerEvent] = []
    fired = threading.Semaphore(0)

    def cb(ev: TimerEvent) -> None:
        events.append(ev)
        fired.release()

    timer = Timer(clock, 1.0, cb)
    try:
        time.sleep(0.05)
        assert events == []
        clock.advance(1.0)
        assert fired.acquire(timeout=2)
        clock.advance(1.0)
        assert fired.acquire(timeout=2)
    finally:
        timer.shutdown()
        timer.join(2)
    assert not timer.is_alive()
    first, second = events[:2]
    assert first.last_expected is None and first.current_expected == pytest.approx(11.0)
    assert second.last_expected == pytest.approx(11.0) and second.current_expected == pytest.approx(12.0)
    assert second.last_duration is not None


def test_timer_oneshot_and_callback_errors() -> None:
    clock = FakeClock(10.0)
    errors: list[BaseException] = []
    calls = threading.Semaphore(0)

    def cb(_ev: TimerEvent) -> None:
        calls.release()
        raise RuntimeError("user bug")

    timer = Timer(clock, 0.5, cb, oneshot=True, on_error=errors.append)
    clock.advance(0.5)
    assert calls.acquire(timeout=2)
    timer.join(2)
    assert not timer.is_alive()
    assert isinstance(errors[0], RuntimeError)


def test_timer_survives_backwards_jump_and_stops_on_shutdown() -> None:
    clock = FakeClock(100.0)
    calls = threading.Semaphore(0)
    timer = Timer(clock, 1.0, lambda _ev: calls.release())
    time.sleep(0.05)
    clock.set(0.0)
    time.sleep(0.05)
    assert timer.is_alive()
    clock.advance(1.0)
    assert calls.acquire(timeout=2)
    clock.shutdown()
    timer.join(1)
    assert not timer.is_alive()


def test_wall_timer_runs_and_stops_promptly() -> None:
    clock = Clock()
    calls = threading.Semaphore(0)
    timer = Timer(clock, 0.02, lambda _ev: calls.release())
    assert calls.acquire(timeout=2) and calls.acquire(timeout=2)
    start = time.monotonic()
    timer.shutdown()
    timer.join(1)
    assert not timer.is_alive() and time.monotonic() - start < 1.0


def test_sim_sleep_counts_from_first_clock_message() -> None:
    clock = FakeClock(0.0)
    t, box = _run(lambda: sleep(clock, 2.0))
    _wait_blocked(t)
    clock.set(100.0)
    _wait_blocked(t)
    clock.set(102.0)
    t.join(2)
    assert not t.is_alive() and "e" not in box


def test_timer_made_in_wall_time_follows_sim_time_after_switch() -> None:
    clock = Clock()
    calls = threading.Semaphore(0)
    timer = Timer(clock, 1.0, lambda _ev: calls.release())
    try:
        time.sleep(0.05)
        clock.switch_to_sim()
        clock.set_time(50)
        time.sleep(0.05)
        clock.set_time(52)
        assert calls.acquire(timeout=2)
    finally:
        clock.shutdown()
        timer.join(2)


def test_timer_and_rate_made_before_sim_time_starts_count_from_the_first_clock() -> None:
    """Simulated time 0 means "no /clock yet" (rospy): the first period starts at the first /clock,
    instead of firing at once with an expected time of 0.5 when /clock jumps to the bag's start."""
    clock = FakeClock(0.0)
    events: list[TimerEvent] = []
    fired = threading.Semaphore(0)
    timer = Timer(clock, 0.5, lambda ev: (events.append(ev), fired.release()), oneshot=True)
    rate = Rate(2, clock)
    t, box = _run(rate.sleep)
    try:
        _wait_blocked(t)
        clock.set(1000.0)
        time.sleep(0.05)
        assert events == [] and t.is_alive()  # neither fires on the first /clock itself
        clock.set(1000.5)
        assert fired.acquire(timeout=2)
        t.join(2)
        assert not t.is_alive() and "e" not in box
    finally:
        timer.shutdown()
        timer.join(2)
    assert events[0].current_expected == pytest.approx(1000.5)

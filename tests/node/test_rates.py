"""``rostopic hz``/``bw``/``delay`` statistics, said once (ninjemys.node.rates): ROS 1's windows and
formulas, the lines they print, and the rostopic facade's ROS 1 classes as adapters over the same
windows (same numbers, same text as the command)."""

from __future__ import annotations

import statistics

import pytest

from ninjemys.node.rates import (
    BandwidthWindow,
    DelayWindow,
    RateWindow,
    bw_text,
    delay_text,
    hz_table,
    hz_text,
)


def test_rate_window_keeps_window_minus_one_gaps_and_restarts_when_time_goes_back():
    w = RateWindow(3)
    for t in (1.0, 1.1, 1.3, 1.6):
        w.arrived(t)
    rate, lo, hi, std, n = w.report()
    assert list(w.gaps) == pytest.approx([0.2, 0.3])
    assert (lo, hi, n) == pytest.approx((0.2, 0.3, 3))
    assert rate == pytest.approx(1 / 0.25) and std == pytest.approx(statistics.pstdev([0.2, 0.3]))
    assert w.report() is None
    w.arrived(0.5)  # before the window's first arrival: a bag looped, a simulation reset
    assert w.report() is None and not w.gaps
    assert RateWindow(-1).window == 50000


def test_delay_window_counts_the_first_message_but_gives_it_no_delay():
    w = DelayWindow(-1)
    w.arrived(10.0, 9.0)
    assert w.report() is None
    w.arrived(10.5, 9.0)
    w.arrived(11.0, 10.5)
    mean, lo, hi, std, n = w.report()
    assert (mean, lo, hi, n) == pytest.approx((1.0, 0.5, 1.5, 3))
    assert std == pytest.approx(0.5)
    assert w.report() is None


def test_bandwidth_window_needs_two_messages_and_scales_units():
    w = BandwidthWindow(0)
    assert w.window == 100
    w.arrived(0.0, 1000)
    assert w.report(1.0) is None
    w.arrived(0.5, 3000)
    stats = w.report(2.0)
    assert stats == pytest.approx((2000.0, 2000.0, 1000, 3000, 2))
    assert bw_text(stats) == "average: 2.00KB/s\n\tmean: 2.00KB min: 1.00KB max: 3.00KB window: 2"
    assert bw_text((500.0, 10.0, 5, 15, 2)).startswith("average: 500.00B/s")
    assert bw_text((2e6, 1e6, 1e6, 1e6, 2)).startswith("average: 2.00MB/s")


def test_lines_are_ros1s():
    assert hz_text(None) == delay_text(None) == hz_table([("/a", None)]) == "no new messages"
    assert hz_text((10.0, 0.09, 0.11, 0.005, 11)) == (
        "average rate: 10.000\n\tmin: 0.090s max: 0.110s std dev: 0.00500s window: 11"
    )
    assert delay_text((0.25, 0.2, 0.3, 0.05, 4)) == (
        "average delay: 0.250\n\tmin: 0.200s max: 0.300s std dev: 0.05000s window: 4"
    )
    table = hz_table(
        [("/a", (10.0, 0.1, 0.1, 0.0, 3)), ("/none", None), ("/long_topic", (2.5, 0.4, 0.4, 0.0, 2))]
    )
    lines = table.splitlines()
    assert lines[0].split() == ["topic", "rate", "min_delta", "max_delta", "std_dev", "window"]
    assert set(lines[1]) == {"="} and len(lines) == 4 and "/none" not in table


def test_the_rostopic_facade_is_an_adapter_over_the_same_windows(capsys):
    import rostopic
    from std_msgs.msg import String

    hz = rostopic.ROSTopicHz(-1, use_wtime=True)
    for _ in range(4):
        hz.callback_hz(String(), topic="/a")
    core = hz._windows["/a"]
    assert isinstance(core, RateWindow) and hz.get_times("/a") == list(core.gaps)
    assert hz.get_msg_tn("/a") == core.last and hz.get_msg_t0("/a") == core.first
    stats = hz.get_hz("/a")
    assert stats is not None and stats[4] == 4
    core.last_reported = None
    hz.print_hz(["/a"])
    assert capsys.readouterr().out == hz_text(stats) + "\n"
    bw = rostopic.ROSTopicBandwidth(2)

    class Raw:
        _buff = b"x" * 10

    for _ in range(3):
        bw.callback(Raw())
    assert bw.sizes == [10, 10] and len(bw.times) == 2
    assert isinstance(rostopic.ROSTopicDelay(-1)._window, DelayWindow)

"""``rostopic hz``, ``bw`` and ``delay`` statistics, said once: ROS 1's windows, formulas and lines.

The ``rostopic`` command (``tools/topic_rates.py``) and the ``rostopic`` facade's ``ROSTopicHz``,
``ROSTopicBandwidth`` and ``ROSTopicDelay`` both keep their samples in these windows and print with
these functions, so the two cannot drift apart. The windows take the time from the caller (ROS time,
wall time, a fake clock in tests) and hold no node: they are plain arithmetic, each guarded by its own
lock because samples arrive on a subscription's worker thread while the main thread reports.
"""

from __future__ import annotations

import math
import threading
from collections import deque
from collections.abc import Sequence

#: ROS 1's window when none is given (``-w`` < 1)
DEFAULT_WINDOW = 50000
#: ``rostopic bw``'s window when none is given
DEFAULT_BW_WINDOW = 100

Stats = tuple[float, float, float, float, int]


def spread(values: Sequence[float]) -> tuple[float, float]:
    """(mean, population standard deviation) of ``values`` (not empty), as ROS 1 computes them."""
    n = len(values)
    mean = sum(values) / n
    return mean, math.sqrt(sum((v - mean) ** 2 for v in values) / n)


class RateWindow:
    """Arrival times of one topic -> ``(rate, min_delta, max_delta, std_dev, window)`` (rostopic hz).

    Keeps at most ``window - 1`` gaps. Time going backwards (a bag looping, a simulation reset)
    restarts the window, as ROS 1's does; :meth:`report` gives nothing twice for the same arrivals.
    """

    def __init__(self, window: int = -1) -> None:
        self.window = window if window > 0 else DEFAULT_WINDOW
        self.gaps: deque[float] = deque(maxlen=max(self.window - 1, 1))
        self.first: float | None = None
        self.last: float | None = None
        self.last_reported: float | None = None
        self.lock = threading.Lock()

    def arrived(self, now: float) -> None:
        """One message arrived at ``now`` (seconds)."""
        with self.lock:
            if self.last is None or self.first is None or now < self.first:
                self.first = self.last = now
                self.gaps.clear()
                return
            self.gaps.append(now - self.last)
            self.last = now

    def reset(self) -> None:
        """Forget everything (ROS time went to zero)."""
        with self.lock:
            self.first = self.last = None
            self.gaps.clear()

    def report(self) -> Stats | None:
        """The statistics since the window started, or None when nothing new arrived."""
        with self.lock:
            if not self.gaps or self.last == self.last_reported:
                return None
            gaps = list(self.gaps)
            self.last_reported = self.last
        mean, std = spread(gaps)
        return (1.0 / mean if mean > 0 else 0.0), min(gaps), max(gaps), std, len(gaps) + 1


class DelayWindow:
    """Header-stamp delays -> ``(mean, min, max, std_dev, window)`` (rostopic delay).

    As ROS 1's: the first message (and the first after time went backwards) starts the window and
    is counted in ``window`` but gives no delay."""

    def __init__(self, window: int = -1) -> None:
        self.window = window if window > 0 else DEFAULT_WINDOW
        self.delays: deque[float] = deque(maxlen=max(self.window - 1, 1))
        self.first: float | None = None
        self.last: float | None = None
        self.last_reported: float | None = None
        self.lock = threading.Lock()

    def arrived(self, now: float, stamp: float) -> None:
        """A message stamped ``stamp`` arrived at ``now`` (seconds of the same clock)."""
        with self.lock:
            if self.first is None or now < self.first:
                self.first = self.last = now
                self.delays.clear()
                return
            self.delays.append(now - stamp)
            self.last = now

    def reset(self) -> None:
        """Forget everything (ROS time went to zero)."""
        with self.lock:
            self.first = self.last = None
            self.delays.clear()

    def report(self) -> Stats | None:
        """The statistics of the window, or None when nothing new arrived."""
        with self.lock:
            if not self.delays or self.last == self.last_reported:
                return None
            self.last_reported = self.last
            delays = list(self.delays)
        mean, std = spread(delays)
        return mean, min(delays), max(delays), std, len(delays) + 1


class BandwidthWindow:
    """Message sizes and arrival (wall) times -> ``(bytes/s, mean, min, max, window)`` (rostopic bw)."""

    def __init__(self, window: int = DEFAULT_BW_WINDOW) -> None:
        self.window = window if window and window > 0 else DEFAULT_BW_WINDOW
        self.samples: deque[tuple[float, int]] = deque(maxlen=self.window)
        self.lock = threading.Lock()

    def arrived(self, now: float, size: int) -> None:
        with self.lock:
            self.samples.append((now, size))

    def report(self, now: float) -> Stats | None:
        """The rate over the window until ``now``; None before two messages, as ROS 1."""
        with self.lock:
            if len(self.samples) < 2:
                return None
            start = self.samples[0][0]
            sizes = [s for _, s in self.samples]
        total = sum(sizes)
        span = now - start
        return (total / span if span > 0 else 0.0), total / len(sizes), min(sizes), max(sizes), len(sizes)


# ------------------------------------------------------------------------------------ ROS 1's lines


def hz_text(stats: Stats | None) -> str:
    """``rostopic hz``'s report for one topic."""
    if stats is None:
        return "no new messages"
    rate, lo, hi, std, window = stats
    return f"average rate: {rate:.3f}\n\tmin: {lo:.3f}s max: {hi:.3f}s std dev: {std:.5f}s window: {window}"


def hz_table(rows: Sequence[tuple[str, Stats | None]]) -> str:
    """``rostopic hz``'s table for several topics (topics without new messages left out)."""
    header = ["topic", "rate", "min_delta", "max_delta", "std_dev", "window"]
    cells = [[str(t), *(f"{v:.4}" for v in s[:4]), str(s[4])] for t, s in rows if s is not None]
    if not cells:
        return "no new messages"
    widths = [max(len(h), *(len(c[i]) for c in cells)) for i, h in enumerate(header)]
    head = "   ".join(h.center(w) for h, w in zip(header, widths, strict=True))
    body = "\n".join("   ".join(c.ljust(w) for c, w in zip(row, widths, strict=True)) for row in cells)
    return f"{head}\n{'=' * (sum(widths) + 3 * (len(header) - 1))}\n{body}\n"


def delay_text(stats: Stats | None) -> str:
    """``rostopic delay``'s report."""
    if stats is None:
        return "no new messages"
    mean, lo, hi, std, window = stats
    return f"average delay: {mean:.3f}\n\tmin: {lo:.3f}s max: {hi:.3f}s std dev: {std:.5f}s window: {window}"


def bw_text(stats: Stats) -> str:
    """``rostopic bw``'s report (bytes, KB or MB by the rate's size, as ROS 1)."""
    rate, mean, lo, hi, window = stats
    scale, unit = (1, "B") if rate < 1000 else (1000, "KB") if rate < 1000000 else (1000000, "MB")
    bw, mean_s, lo_s, hi_s = (f"{v / scale:.2f}{unit}" for v in (rate, mean, lo, hi))
    return f"average: {bw}/s\n\tmean: {mean_s} min: {lo_s} max: {hi_s} window: {window}"

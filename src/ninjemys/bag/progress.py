"""A terminal progress bar with percentage, throughput and ETA (compress, reindex, export ...).

It draws only when its stream is a terminal, at most ten times a second, and leaves one finished line
behind; on a pipe or in a test it prints nothing, so scripted output stays clean.
"""

from __future__ import annotations

import shutil
import sys
import time
from typing import TextIO

from ninjemys.bag.info import human_size


class Progress:
    """``step(done)`` as work advances (bytes), ``finish()`` at the end."""

    def __init__(
        self, label: str, total: int, stream: TextIO | None = None, enabled: bool | None = None
    ) -> None:
        self.label = label
        self.total = max(total, 1)
        self.stream = stream or sys.stderr
        self.enabled = self.stream.isatty() if enabled is None else enabled
        self.started = time.monotonic()
        self._last_draw = 0.0
        self.done = 0

    def step(self, done: int) -> None:
        self.done = done
        now = time.monotonic()
        if self.enabled and now - self._last_draw >= 0.1:
            self._last_draw = now
            self._draw(now, final=False)

    def finish(self) -> None:
        self.done = self.total
        if self.enabled:
            self._draw(time.monotonic(), final=True)
            self.stream.write("\n")
            self.stream.flush()

    def line(self, now: float, final: bool) -> str:
        """The text of the bar at time ``now`` (pure, so it can be tested)."""
        elapsed = max(now - self.started, 1e-9)
        fraction = min(self.done / self.total, 1.0)
        rate = self.done / elapsed
        if final:
            clock = _clock(elapsed)
            tail = f"{clock}    "
        elif rate > 0:
            tail = f"{_clock((self.total - self.done) / rate)} ETA"
        else:
            tail = "--:-- ETA"
        width = shutil.get_terminal_size((80, 20)).columns
        info = f" {fraction * 100:3.0f}% {human_size(self.done):>9} {human_size(rate):>9}/s {tail}"
        label = self.label if len(self.label) <= 30 else "..." + self.label[-27:]
        bar_width = max(width - len(label) - len(info) - 5, 10)
        filled = int(bar_width * fraction)
        return f"{label} [{'=' * filled}{' ' * (bar_width - filled)}]{info}"

    def _draw(self, now: float, final: bool) -> None:
        self.stream.write("\r" + self.line(now, final))
        self.stream.flush()


def _clock(seconds: float) -> str:
    seconds = int(seconds)
    hours, rest = divmod(seconds, 3600)
    mins, secs = divmod(rest, 60)
    return f"{hours}:{mins:02d}:{secs:02d}" if hours else f"{mins:02d}:{secs:02d}"

"""``rostopic hz``, ``bw`` and ``delay``: rates from raw arrivals (hz and bw never deserialize)."""

from __future__ import annotations

import argparse
import math
import sys
import threading
import time
from collections import deque
from collections.abc import Callable
from typing import Any

from ninjemys.tools.cli import master
from ninjemys.tools.topic_common import ID, class_for, compile_filter, make_node, resolve_topic, wait_for_type


class RateStats:
    """rostopic hz's statistics over a window of inter-arrival gaps (ROS 1's formulas)."""

    def __init__(self, window: int) -> None:
        self.window = window if window > 0 else 50000
        self.gaps: deque[float] = deque(maxlen=self.window - 1 if self.window > 1 else 1)
        self.last: float | None = None
        self.last_printed: float | None = None
        self.lock = threading.Lock()

    def arrived(self, now: float) -> None:
        with self.lock:
            if self.last is None or now < self.last:
                self.last = now
                self.gaps.clear()
                return
            self.gaps.append(now - self.last)
            self.last = now

    def report(self) -> tuple[float, float, float, float, int] | None:
        with self.lock:
            if not self.gaps or self.last == self.last_printed:
                return None
            gaps = list(self.gaps)
            self.last_printed = self.last
        n = len(gaps)
        mean = sum(gaps) / n
        rate = 1.0 / mean if mean > 0 else 0.0
        std = math.sqrt(sum((g - mean) ** 2 for g in gaps) / n)
        return rate, min(gaps), max(gaps), std, n + 1


def cmd_hz(args: argparse.Namespace) -> int:
    from ninjemys.node.clock import for_node

    client = master(ID)
    node = make_node()
    try:
        clock = None if args.wall_time else for_node(node)
        stats: dict[str, RateStats] = {}
        predicate = compile_filter(args.filter_expr)
        for raw_topic in args.topics:
            topic = resolve_topic(raw_topic)
            ttype, real, _ = wait_for_type(client, topic)
            rate = stats[raw_topic] = RateStats(args.window)
            now = time.time if clock is None else clock.now
            node.subscriber(real, None, _hz_callback(rate, now, predicate, ttype, real), raw=True)
            print(f"subscribed to [{real}]")
        if clock is not None and not clock.is_wallclock:
            print("WARNING: may be using simulated time", file=sys.stderr)
        while not node.is_shutdown:
            time.sleep(1.0)
            _print_rates(stats)
    finally:
        node.shutdown("rostopic hz done")
    return 0


def _hz_callback(
    stats: RateStats, now: Callable[[], float], predicate: Any, ttype: str, topic: str
) -> Callable[[Any], None]:
    if predicate is None:
        return lambda raw: stats.arrived(now())
    cls_holder: list[Any] = []

    def filtered(raw: Any) -> None:
        if not cls_holder:
            cls_holder.append(class_for(ttype, raw.connection_header))
        if predicate(cls_holder[0].deserialize_from(raw.data), topic):
            stats.arrived(now())

    return filtered


def _print_rates(stats: dict[str, RateStats]) -> None:
    if len(stats) == 1:
        result = next(iter(stats.values())).report()
        if result is None:
            print("no new messages")
            return
        rate, lo, hi, std, window = result
        print(
            f"average rate: {rate:.3f}\n\tmin: {lo:.3f}s max: {hi:.3f}s std dev: {std:.5f}s window: {window}"
        )
        return
    header = ["topic", "rate", "min_delta", "max_delta", "std_dev", "window"]
    cols: dict[str, list[str]] = {h: [] for h in header}
    for topic, stat in stats.items():
        result = stat.report()
        if result is None:
            continue
        rate, lo, hi, std, window = result
        for key, value in zip(
            header, (topic, f"{rate:.4}", f"{lo:.4}", f"{hi:.4}", f"{std:.4}", str(window)), strict=True
        ):
            cols[key].append(value)
    if not cols["topic"]:
        print("no new messages")
        return
    widths = [max(len(h), *(len(v) for v in cols[h])) for h in header]
    print("   ".join(h.center(w) for h, w in zip(header, widths, strict=True)))
    print("=" * (sum(widths) + 3 * (len(header) - 1)))
    for i in range(len(cols["topic"])):
        print("   ".join(cols[h][i].ljust(w) for h, w in zip(header, widths, strict=True)))
    print()


def cmd_bw(args: argparse.Namespace) -> int:
    client = master(ID)
    topic = resolve_topic(args.topic)
    _, real, _ = wait_for_type(client, topic)
    window = args.window if args.window and args.window > 0 else 100
    samples: deque[tuple[float, int]] = deque(maxlen=window)
    lock = threading.Lock()

    def arrived(raw: Any) -> None:
        with lock:
            samples.append((time.time(), len(raw.data)))

    node = make_node()
    try:
        node.subscriber(real, None, arrived, raw=True)
        print(f"subscribed to [{real}]")
        while not node.is_shutdown:
            time.sleep(1.0)
            with lock:
                if len(samples) < 2:
                    continue
                now = time.time()
                sizes = [s for _, s in samples]
                span = now - samples[0][0]
            total = sum(sizes)
            rate = total / span if span > 0 else 0.0
            print(
                "average: %s/s\n\tmean: %s min: %s max: %s window: %s"
                % (*_units(rate, total / len(sizes), min(sizes), max(sizes)), len(sizes))
            )
    finally:
        node.shutdown("rostopic bw done")
    return 0


def _units(rate: float, *values: float) -> list[str]:
    if rate < 1000:
        return [f"{v:.2f}B" for v in (rate, *values)]
    if rate < 1000000:
        return [f"{v / 1000:.2f}KB" for v in (rate, *values)]
    return [f"{v / 1000000:.2f}MB" for v in (rate, *values)]


def cmd_delay(args: argparse.Namespace) -> int:
    from ninjemys.node.clock import for_node

    client = master(ID)
    topic = resolve_topic(args.topic)
    ttype, real, _ = wait_for_type(client, topic)
    node = make_node()
    try:
        clock = for_node(node)
        delays: deque[float] = deque(maxlen=args.window if args.window and args.window > 0 else 50000)
        lock = threading.Lock()
        cls_holder: list[Any] = []
        fresh = threading.Event()

        def arrived(raw: Any) -> None:
            now = clock.now()
            if not cls_holder:
                cls_holder.append(class_for(ttype, raw.connection_header))
                if not cls_holder[0]._has_header:
                    print("msg does not have header", file=sys.stderr)
            msg = cls_holder[0].deserialize_from(raw.data)
            if not getattr(msg, "_has_header", False):
                return
            with lock:
                delays.append(now - msg.header.stamp.to_sec())
            fresh.set()

        node.subscriber(real, None, arrived, raw=True)
        print(f"subscribed to [{real}]")
        while not node.is_shutdown:
            time.sleep(1.0)
            if not fresh.is_set():
                print("no new messages")
                continue
            fresh.clear()
            with lock:
                values = list(delays)
            n = len(values)
            mean = sum(values) / n
            std = math.sqrt(sum((d - mean) ** 2 for d in values) / n)
            print(
                f"average delay: {mean:.3f}\n\tmin: {min(values):.3f}s max: {max(values):.3f}s std dev: {std:.5f}s window: {n}"
            )
    finally:
        node.shutdown("rostopic delay done")
    return 0

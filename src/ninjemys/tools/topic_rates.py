"""``rostopic hz``, ``bw`` and ``delay``: rates from raw arrivals (hz and bw never deserialize).

The windows and ROS 1's lines are ninjemys.node.rates (shared with the rostopic facade); this
module subscribes and prints once a second."""

from __future__ import annotations

import argparse
import sys
import threading
import time
from collections.abc import Callable
from typing import Any

from ninjemys.node.rates import (
    BandwidthWindow,
    DelayWindow,
    RateWindow,
    bw_text,
    delay_text,
    hz_table,
    hz_text,
)
from ninjemys.tools.cli import master
from ninjemys.tools.topic_common import ID, class_for, compile_filter, make_node, resolve_topic, wait_for_type


def cmd_hz(args: argparse.Namespace) -> int:
    from ninjemys.node.clock import for_node

    client = master(ID)
    node = make_node()
    try:
        clock = None if args.wall_time else for_node(node)
        stats: dict[str, RateWindow] = {}
        predicate = compile_filter(args.filter_expr)
        for raw_topic in args.topics:
            topic = resolve_topic(raw_topic)
            ttype, real, _ = wait_for_type(client, topic)
            rate = stats[raw_topic] = RateWindow(args.window)
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
    stats: RateWindow, now: Callable[[], float], predicate: Any, ttype: str, topic: str
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


def _print_rates(stats: dict[str, RateWindow]) -> None:
    if len(stats) == 1:
        print(hz_text(next(iter(stats.values())).report()))
        return
    print(hz_table([(topic, window.report()) for topic, window in stats.items()]))


def cmd_bw(args: argparse.Namespace) -> int:
    client = master(ID)
    topic = resolve_topic(args.topic)
    _, real, _ = wait_for_type(client, topic)
    window = BandwidthWindow(args.window or 0)
    node = make_node()
    try:
        node.subscriber(real, None, lambda raw: window.arrived(time.time(), len(raw.data)), raw=True)
        print(f"subscribed to [{real}]")
        while not node.is_shutdown:
            time.sleep(1.0)
            stats = window.report(time.time())
            if stats is not None:
                print(bw_text(stats))
    finally:
        node.shutdown("rostopic bw done")
    return 0


def cmd_delay(args: argparse.Namespace) -> int:
    from ninjemys.node.clock import for_node

    client = master(ID)
    topic = resolve_topic(args.topic)
    ttype, real, _ = wait_for_type(client, topic)
    node = make_node()
    try:
        clock = for_node(node)
        window = DelayWindow(args.window or 0)
        cls_holder: list[Any] = []
        warned = threading.Event()

        def arrived(raw: Any) -> None:
            now = clock.now()
            if not cls_holder:
                cls_holder.append(class_for(ttype, raw.connection_header))
            if not cls_holder[0]._has_header:
                if not warned.is_set():
                    warned.set()
                    print("msg does not have header", file=sys.stderr)
                return
            window.arrived(now, cls_holder[0].deserialize_from(raw.data).header.stamp.to_sec())

        node.subscriber(real, None, arrived, raw=True)
        print(f"subscribed to [{real}]")
        while not node.is_shutdown:
            time.sleep(1.0)
            print(delay_text(window.report()))
    finally:
        node.shutdown("rostopic delay done")
    return 0

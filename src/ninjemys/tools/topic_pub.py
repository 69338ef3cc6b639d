"""``rostopic pub``: one message, a rate, or YAML documents from a file, with ROS 1's output."""

from __future__ import annotations

import argparse
import sys
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

from ninjemys.errors import MasterError, TypeNotFoundError
from ninjemys.master.graph import GraphSnapshot
from ninjemys.tools.cli import master
from ninjemys.tools.topic_common import ID, TopicToolError, make_node, resolve_topic

ONCE_DELAY = 3.0


def _yaml_documents(path: str) -> Iterator[Any]:
    from ninjemys.paramyaml import load_yaml_documents

    text = sys.stdin.read() if path == "-" else Path(path).read_text()
    for doc in load_yaml_documents(text):
        if doc is not None:
            yield doc


def cmd_pub(args: argparse.Namespace) -> int:
    from ninjemys.idl.loader import get_message_class
    from ninjemys.tools.msgargs import fill_message_args, parse_yaml_args, substitution_keys

    topic = resolve_topic(args.topic)
    try:
        cls = get_message_class(args.type)
    except TypeNotFoundError:
        raise TopicToolError(
            f"Cannot load message class for [{args.type}]. Are your messages built?"
        ) from None
    values = parse_yaml_args(args.args)
    if args.file and values:
        raise TopicToolError("cannot use both -f and message arguments")

    def build(doc_args: list[Any]) -> Any:
        from ninjemys.rostime import Time

        msg = cls()
        fill_message_args(msg, doc_args, substitution_keys(Time.now()))
        return msg

    node = make_node()
    try:
        latch = args.latch or args.rate is None
        pub = node.publisher(topic, cls, queue_size=100, latch=latch)
        _await_subscribers(node, pub, master(ID), topic)
        if args.file:
            messages = [build([doc]) for doc in _yaml_documents(args.file)]
            period = 1.0 / args.rate if args.rate else 0.1
            for msg in messages:
                if node.is_shutdown:
                    break
                pub.publish(msg)
                time.sleep(period)
            if args.once or args.rate is None:
                _linger(node, pub, client=master(ID), topic=topic)
            return 0
        msg = build(values)
        if args.rate is None:
            suffix = f" for {ONCE_DELAY:g} seconds" if args.once else ". Press ctrl-C to terminate"
            text = f"publishing and latching [{msg}]" if args.verbose else "publishing and latching message"
            print(text + suffix, flush=True)
            pub.publish(msg)
            if args.once:
                _linger(node, pub, client=master(ID), topic=topic)
            else:
                node.wait_for_shutdown()
            return 0
        period = 1.0 / args.rate
        deadline = time.monotonic()
        while not node.is_shutdown:
            if args.substitute:
                msg = build(values)
            if args.verbose:
                print(f"publishing {msg}")
            pub.publish(msg)
            if args.once:
                _linger(node, pub, client=master(ID), topic=topic)
                break
            deadline += period
            delay = deadline - time.monotonic()
            if delay > 0:
                time.sleep(delay)
            else:
                deadline = time.monotonic()
    finally:
        node.shutdown("rostopic pub done")
    return 0


def _await_subscribers(node: Any, pub: Any, client: Any, topic: str, timeout: float = 1.0) -> None:
    """Give the subscribers the master already knows up to ``timeout`` to connect before the first
    publish, so a short ``rostopic pub`` does not lose its first messages (ros_comm#176)."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline and not node.is_shutdown:
        try:
            expected = len(GraphSnapshot.fetch(client, with_types=False).subscribers.get(topic, []))
        except MasterError:
            return
        if pub.get_num_connections() >= expected:
            return
        time.sleep(0.02)


def _linger(node: Any, pub: Any, client: Any, topic: str) -> None:
    """``-1``: keep the latched message available for up to 3 s, leaving early once every
    subscriber the master knows has connected (ROS 1 always sleeps the full 3 s)."""
    deadline = time.monotonic() + ONCE_DELAY
    while time.monotonic() < deadline and not node.is_shutdown:
        try:
            expected = len(GraphSnapshot.fetch(client, with_types=False).subscribers.get(topic, []))
        except MasterError:
            expected = 0
        if expected and pub.get_num_connections() >= expected:
            time.sleep(0.1)  # let the kernel deliver the latched frame before we close
            return
        time.sleep(0.05)


def split_pub_options(argv: list[str]) -> list[str]:
    """``rostopic pub /t -r 10 Type args`` puts options anywhere (optparse did): move them first,
    leaving YAML values such as ``-1.5`` or ``'{x: -1}'`` positional."""
    if not argv or argv[0] != "pub":
        return argv
    opts, rest = [], []
    it = iter(argv[1:])
    positional_seen = 0
    for arg in it:
        if arg in ("-r", "--rate", "-f", "--file"):
            opts.extend([arg, next(it, "")])
        elif arg in ("-v", "-1", "--once", "-l", "--latch", "-s", "--substitute-keywords"):
            opts.append(arg)
        elif (
            arg.startswith("--rate=")
            or arg.startswith("--file=")
            or (arg.startswith("-r") and arg[2:].replace(".", "").isdigit())
        ):
            opts.append(arg)
        else:
            rest.append(arg)
            positional_seen += 1
    return ["pub", *opts, *rest[:2], *(["--"] if len(rest) > 2 else []), *rest[2:]]

"""``rostopic``: list, info, type, find, echo, pub, hz, bw and delay, with ROS 1's output.

Built on the core :class:`~ninjemys.node.Node`. ``hz`` and ``bw`` subscribe raw and never
deserialize (ROS 1 deserializes every message just to count it); ``echo`` decodes topics of types
ninjemys does not ship from the publisher's own ``message_definition``.
"""

from __future__ import annotations

import argparse
import math
import os
import sys
import threading
import time
from collections import deque
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

from ninjemys import names
from ninjemys.errors import MasterError, NinjemysError, TypeNotFoundError
from ninjemys.tools.cli import Subcommands, entry, master
from ninjemys.tools.graph import GraphState, node_api

NAME = "rostopic"
ID = "/rostopic"
ONCE_DELAY = 3.0
USAGE = """rostopic is a command-line tool for printing information about ROS Topics.

Commands:
\trostopic bw\tdisplay bandwidth used by topic
\trostopic delay\tdisplay delay of topic from timestamp in header
\trostopic echo\tprint messages to screen
\trostopic find\tfind topics by type
\trostopic hz\tdisplay publishing rate of topic
\trostopic info\tprint information about active topic
\trostopic list\tlist active topics
\trostopic pub\tpublish data to topic
\trostopic type\tprint topic or field type

Type rostopic <command> -h for more detailed usage, e.g. 'rostopic echo -h'
"""


class TopicToolError(NinjemysError):
    """A rostopic usage or lookup error."""


def _resolve(name: str) -> str:
    return names.resolve_name(name, names.get_ros_namespace() + NAME)


# ----------------------------------------------------------------------------------- list / info


def _cmd_list(args: argparse.Namespace) -> int:
    if args.bag:
        return _list_bag(args.bag)
    if args.subscribers_only and args.publishers_only:
        raise TopicToolError("cannot specify both subscribers- and publishers-only")
    state = GraphState.fetch(master(ID))
    pubs = [(t, state.type_of(t), n) for t, n in state.publishers.items()]
    subs = [(t, state.type_of(t), n) for t, n in state.subscribers.items()]
    if args.namespace:
        topic = _resolve(args.namespace)
        ns = names.make_global_ns(topic)
        pubs = [x for x in pubs if x[0] == topic or x[0].startswith(ns)]
        subs = [x for x in subs if x[0] == topic or x[0].startswith(ns)]
    if args.host:
        client = master(ID)
        cache: dict[str, str | None] = {}
        for host in sorted(_hosts(client, pubs + subs, cache)):
            hpubs = _on_host(client, pubs, host, cache)
            hsubs = _on_host(client, subs, host, cache)
            if (hpubs and not args.subscribers_only) or (hsubs and not args.publishers_only):
                print(f"Host [{host}]:")
                _print_list(hpubs, hsubs, args, indent="  ")
        return 0
    _print_list(pubs, subs, args)
    return 0


def _hosts(client: Any, entries: list[Any], cache: dict[str, str | None]) -> set[str]:
    from urllib.parse import urlparse

    hosts = set()
    for _, _, nodes in entries:
        for node in nodes:
            if node not in cache:
                cache[node] = node_api(client, node)
            if cache[node]:
                hosts.add(urlparse(cache[node]).hostname or "")
    return hosts


def _on_host(client: Any, entries: list[Any], host: str, cache: dict[str, str | None]) -> list[Any]:
    from urllib.parse import urlparse

    out = []
    for topic, ttype, nodes in entries:
        members = [n for n in nodes if cache.get(n) and urlparse(cache[n]).hostname == host]
        if members:
            out.append((topic, ttype, members))
    return out


def _print_list(pubs: list[Any], subs: list[Any], args: argparse.Namespace, indent: str = "") -> None:
    if args.verbose:
        if not args.subscribers_only:
            print(f"\n{indent}Published topics:")
            for topic, ttype, nodes in pubs:
                count = f"{len(nodes)} publishers" if len(nodes) > 1 else "1 publisher"
                print(f"{indent} * {topic} [{ttype}] {count}")
        if not args.publishers_only:
            print(indent)
            print(f"{indent}Subscribed topics:")
            for topic, ttype, nodes in subs:
                count = f"{len(nodes)} subscribers" if len(nodes) > 1 else "1 subscriber"
                print(f"{indent} * {topic} [{ttype}] {count}")
        print("")
        return
    if args.publishers_only:
        topics = [t for t, _, _ in pubs]
    elif args.subscribers_only:
        topics = [t for t, _, _ in subs]
    else:
        topics = list({t for t, _, _ in pubs} | {t for t, _, _ in subs})
    print("\n".join(f"{indent}{t}" for t in sorted(topics)))


def _list_bag(path: str) -> int:
    from ninjemys.bag.api import Bag

    if not os.path.exists(path):
        raise TopicToolError(f"bag file [{path}] does not exist")
    seen: set[str] = set()
    with Bag(path) as bag:
        for topic, _, _ in bag.read_messages(raw=True):
            if topic not in seen:
                print(topic)
                seen.add(topic)
    return 0


def info_text(topic: str, client: Any) -> str:
    state = GraphState.fetch(client)
    pubs = state.publishers.get(topic, [])
    subs = state.subscribers.get(topic, [])
    if not pubs and not subs:
        raise TopicToolError(f"Unknown topic {topic}")
    out = [f"Type: {state.type_of(topic) or 'unknown type'}\n\n"]
    for title, nodes in (("Publishers", pubs), ("Subscribers", subs)):
        if nodes:
            out.append(f"{title}: \n")
            out.extend(f" * {n} ({node_api(client, n)})\n" for n in nodes)
        else:
            out.append(f"{title}: None\n")
        out.append("\n")
    return "".join(out)


def _cmd_info(args: argparse.Namespace) -> int:
    print(info_text(_resolve(args.topic), master(ID)))
    return 0


# ------------------------------------------------------------------------------- type / find


def topic_type(client: Any, topic: str) -> tuple[str | None, str | None, str | None]:
    """(type, real topic, field path) for ``/topic`` or ``/topic/field/sub`` (longest topic prefix)."""
    types = dict(client.get_topic_types())
    if topic in types:
        return types[topic], topic, None
    candidates = [t for t in types if topic.startswith(t + "/")]
    if not candidates:
        return None, None, None
    real = max(candidates, key=len)
    return types[real], real, topic[len(real) + 1 :]


def _cmd_type(args: argparse.Namespace) -> int:
    from ninjemys.idl.loader import get_message_class

    topic = _resolve(args.topic)
    ttype, real, field = topic_type(master(ID), topic)
    if ttype is None:
        print(f"unknown topic type [{topic}]", file=sys.stderr)
        return 1
    if not field:
        print(ttype)
        return 0
    field_type = ttype
    for part in field.split("/"):
        cls = get_message_class(field_type.split("[")[0])
        if part not in cls.__slots__:
            raise TopicToolError(f"no field named [{part}] in {field_type}")
        field_type = cls._slot_types[cls.__slots__.index(part)]
    print(f"{ttype} {field} {field_type}")
    return 0


def _cmd_find(args: argparse.Namespace) -> int:
    client = master(ID)
    wanted = args.type
    topics = sorted(t for t, ttype in client.get_published_topics("/") if ttype == wanted)
    print("\n".join(topics))
    return 0


# -------------------------------------------------------------------------------- subscribing


def _make_node(name: str = "rostopic") -> Any:
    from ninjemys.node import Node

    return Node(name, anonymous=True)


def _wait_for_type(client: Any, topic: str, announce: bool = True) -> tuple[str, str, str | None]:
    """Block until the topic (or a topic owning this field path) has a known type, as ROS 1 does."""
    ttype, real, field = topic_type(client, topic)
    if ttype is not None:
        return ttype, real, field  # type: ignore[return-value]
    if announce:
        sys.stderr.write(f"WARNING: topic [{topic}] does not appear to be published yet\n")
    while True:
        time.sleep(0.1)
        ttype, real, field = topic_type(client, topic)
        if ttype is not None:
            return ttype, real, field  # type: ignore[return-value]


def _class_for(ttype: str, header: Any) -> Any:
    from ninjemys.idl.loader import get_message_class, message_class_from_definition

    try:
        return get_message_class(ttype)
    except TypeNotFoundError:
        definition = header.get("message_definition") if header else None
        if not definition:
            raise TopicToolError(
                f"Cannot load message class for [{ttype}]. Are your messages built?"
            ) from None
        return message_class_from_definition(ttype, definition, header.get("md5sum"))


def field_getter(path: str | None) -> Callable[[Any], Any] | None:
    """``/field/sub[0]`` or ``field/arr[1:3]`` -> a function extracting it from a message."""
    if not path:
        return None
    steps: list[tuple[str, slice | int | None]] = []
    for part in (p for p in path.split("/") if p):
        index: slice | int | None = None
        if "[" in part:
            name, rest = part.split("[", 1)
            if not rest.endswith("]"):
                raise TopicToolError(f"missing closing ']' in slice spec '{part}'")
            spec = rest[:-1]
            try:
                if ":" in spec:
                    bounds = [int(x) if x else None for x in spec.split(":")]
                    index = slice(*bounds)
                else:
                    index = int(spec)
            except ValueError:
                raise TopicToolError(f"field '{name}' has invalid slice argument '{spec}'") from None
        else:
            name = part
        steps.append((name, index))

    def get(msg: Any) -> Any:
        value = msg
        for name, index in steps:
            if name:
                try:
                    value = getattr(value, name)
                except AttributeError:
                    raise TopicToolError(f"no field named {name} in {path}") from None
            if index is not None:
                value = value[index]
        return value

    return get


def _cmd_echo(args: argparse.Namespace) -> int:
    from ninjemys.tools.echo_format import EchoPrinter

    topic = _resolve(args.topic)
    if args.bag:
        return _echo_bag(args, topic)
    client = master(ID)
    ttype, real, field = _wait_for_type(client, topic)
    printer = EchoPrinter(
        plot=args.plot,
        clear=args.clear,
        noarr=args.noarr,
        nostr=args.nostr,
        offset=args.offset_time,
        width=args.fixed_numeric_width,
    )
    getter = field_getter(field)
    predicate = _compile_filter(args.filter_expr)
    node = _make_node()
    done = threading.Event()
    state: dict[str, Any] = {"count": 0, "cls": None}

    def on_message(raw: Any) -> None:
        # runs on the subscription's own worker thread: printing here costs no extra thread hop
        if done.is_set():
            return
        if state["cls"] is None:
            state["cls"] = _class_for(ttype, raw.connection_header)
        msg = state["cls"].deserialize_from(raw.data)
        if predicate is not None and not predicate(msg, real):
            return
        value = getter(msg) if getter else msg
        if value is None:
            return
        try:
            sys.stdout.write(printer.render(value))
            sys.stdout.flush()
        except BrokenPipeError:
            done.set()
            return
        state["count"] += 1
        if args.count and state["count"] >= args.count:
            done.set()

    try:
        node.subscriber(real, None, on_message, raw=True, queue_size=args.queue_size)
        while not done.wait(0.5) and not node.is_shutdown:
            pass
    finally:
        node.shutdown("rostopic echo done")
    return 0


def _echo_bag(args: argparse.Namespace, topic: str) -> int:
    from ninjemys.bag.api import Bag
    from ninjemys.tools.echo_format import EchoPrinter

    printer = EchoPrinter(plot=args.plot, clear=args.clear, noarr=args.noarr, nostr=args.nostr)
    count = 0
    with Bag(args.bag) as bag:
        for btopic, msg, _ in bag.read_messages():
            if btopic != topic and not topic.startswith(btopic + "/"):
                continue
            getter = field_getter(topic[len(btopic) :]) if topic != btopic else None
            sys.stdout.write(printer.render(getter(msg) if getter else msg))
            count += 1
            if args.count and count >= args.count:
                break
    return 0


def _compile_filter(expr: str | None) -> Callable[[Any, str], bool] | None:
    if not expr:
        return None
    try:
        code = compile(expr, "<--filter>", "eval")
    except SyntaxError as exc:
        raise TopicToolError(f"invalid --filter expression {expr!r}: {exc.msg}") from None

    def predicate(msg: Any, topic: str) -> bool:
        return bool(eval(code, {"m": msg, "topic": topic, "math": math}))  # noqa: S307 - the user's own expression

    return predicate


# --------------------------------------------------------------------------------- hz / bw / delay


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


def _cmd_hz(args: argparse.Namespace) -> int:
    from ninjemys.node.clock import for_node

    client = master(ID)
    node = _make_node()
    try:
        clock = None if args.wall_time else for_node(node)
        stats: dict[str, RateStats] = {}
        predicate = _compile_filter(args.filter_expr)
        for raw_topic in args.topics:
            topic = _resolve(raw_topic)
            ttype, real, _ = _wait_for_type(client, topic)
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
            cls_holder.append(_class_for(ttype, raw.connection_header))
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


def _cmd_bw(args: argparse.Namespace) -> int:
    client = master(ID)
    topic = _resolve(args.topic)
    _, real, _ = _wait_for_type(client, topic)
    window = args.window if args.window and args.window > 0 else 100
    samples: deque[tuple[float, int]] = deque(maxlen=window)
    lock = threading.Lock()

    def arrived(raw: Any) -> None:
        with lock:
            samples.append((time.time(), len(raw.data)))

    node = _make_node()
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


def _cmd_delay(args: argparse.Namespace) -> int:
    from ninjemys.node.clock import for_node

    client = master(ID)
    topic = _resolve(args.topic)
    ttype, real, _ = _wait_for_type(client, topic)
    node = _make_node()
    try:
        clock = for_node(node)
        delays: deque[float] = deque(maxlen=args.window if args.window and args.window > 0 else 50000)
        lock = threading.Lock()
        cls_holder: list[Any] = []
        fresh = threading.Event()

        def arrived(raw: Any) -> None:
            now = clock.now()
            if not cls_holder:
                cls_holder.append(_class_for(ttype, raw.connection_header))
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


# ------------------------------------------------------------------------------------------ pub


def _yaml_documents(path: str) -> Iterator[Any]:
    from ninjemys.paramyaml import load_yaml_documents

    text = sys.stdin.read() if path == "-" else Path(path).read_text()
    for doc in load_yaml_documents(text):
        if doc is not None:
            yield doc


def _cmd_pub(args: argparse.Namespace) -> int:
    from ninjemys.idl.loader import get_message_class
    from ninjemys.tools.msgargs import fill_message_args, parse_yaml_args, substitution_keys

    topic = _resolve(args.topic)
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

    node = _make_node()
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
            expected = len(GraphState.fetch(client, with_types=False).subscribers.get(topic, []))
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
            expected = len(GraphState.fetch(client, with_types=False).subscribers.get(topic, []))
        except MasterError:
            expected = 0
        if expected and pub.get_num_connections() >= expected:
            time.sleep(0.1)  # let the kernel deliver the latched frame before we close
            return
        time.sleep(0.05)


# -------------------------------------------------------------------------------------- parsing


def _parser(command: str) -> argparse.ArgumentParser | None:
    sub = Subcommands(NAME, command)
    p = sub.add("list")
    p.add_argument("namespace", nargs="?")
    p.add_argument("-b", "--bag", help="list topics in .bag file")
    p.add_argument("-v", "--verbose", action="store_true", help="list full details about each topic")
    p.add_argument("-p", dest="publishers_only", action="store_true", help="list only publishers")
    p.add_argument("-s", dest="subscribers_only", action="store_true", help="list only subscribers")
    p.add_argument("--host", action="store_true", help="group by host name")
    p.set_defaults(run=_cmd_list)
    p = sub.add("info")
    p.add_argument("topic")
    p.set_defaults(run=_cmd_info)
    p = sub.add("type")
    p.add_argument("topic")
    p.set_defaults(run=_cmd_type)
    p = sub.add("find")
    p.add_argument("type")
    p.set_defaults(run=_cmd_find)
    p = sub.add("echo")
    p.add_argument("topic")
    p.add_argument("-b", "--bag", help="echo messages from .bag file")
    p.add_argument("-p", dest="plot", action="store_true", help="echo in a plotting friendly format")
    p.add_argument("-w", dest="fixed_numeric_width", type=int, help="fixed width for numeric values")
    p.add_argument("--filter", dest="filter_expr", help="Python expression over m and topic")
    p.add_argument("--nostr", action="store_true", help="exclude string fields")
    p.add_argument("--noarr", action="store_true", help="exclude arrays")
    p.add_argument("-c", "--clear", action="store_true", help="clear screen before printing next message")
    p.add_argument("-a", "--all", dest="all_topics", action="store_true", help="display all message in bag")
    p.add_argument("-n", dest="count", type=int, help="number of messages to echo")
    p.add_argument("--offset", dest="offset_time", action="store_true", help="display time as offsets")
    p.add_argument("--queue-size", dest="queue_size", type=int, default=None)
    p.set_defaults(run=_cmd_echo)
    p = sub.add("pub")
    p.add_argument("topic")
    p.add_argument("type")
    p.add_argument("args", nargs=argparse.REMAINDER)
    p.add_argument("-v", dest="verbose", action="store_true", help="print verbose output")
    p.add_argument("-r", "--rate", type=float, help="publishing rate (hz)")
    p.add_argument("-1", "--once", action="store_true", help="publish one message and exit")
    p.add_argument("-f", "--file", help="read args from YAML file (Bagy)")
    p.add_argument("-l", "--latch", action="store_true", help="enable latching for -f, -r and piped input")
    p.add_argument("-s", "--substitute-keywords", dest="substitute", action="store_true")
    p.set_defaults(run=_cmd_pub)
    p = sub.add("hz")
    p.add_argument("topics", nargs="+")
    p.add_argument("-w", "--window", type=int, default=-1, help="window size, in # of messages")
    p.add_argument("--filter", dest="filter_expr", help="only measure messages matching the expression")
    p.add_argument(
        "--wall-time", dest="wall_time", action="store_true", help="calculates rate using wall time"
    )
    p.add_argument("--tcpnodelay", action="store_true")
    p.set_defaults(run=_cmd_hz)
    p = sub.add("bw")
    p.add_argument("topic")
    p.add_argument("-w", "--window", type=int, default=-1)
    p.set_defaults(run=_cmd_bw)
    p = sub.add("delay")
    p.add_argument("topic")
    p.add_argument("-w", "--window", type=int, default=-1)
    p.add_argument("--tcpnodelay", action="store_true")
    p.set_defaults(run=_cmd_delay)
    return sub.parser if sub.matched else None


def _split_pub_options(argv: list[str]) -> list[str]:
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


def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    if not argv or argv[0] in ("-h", "--help", "help"):
        print(USAGE)
        return 0 if argv else 1
    parser = _parser(argv[0])
    if parser is None:
        print(USAGE)
        return 1
    args = parser.parse_args(_split_pub_options(argv))
    if args.command is None:
        print(USAGE)
        return 1
    if args.command == "pub" and args.args and args.args[0] == "--":
        args.args = args.args[1:]
    return args.run(args)


console_main = entry(main)

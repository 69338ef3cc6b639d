"""``rostopic``: list, info, type, find, echo, pub, hz, bw and delay, with ROS 1's output.

Built on the core :class:`~ninjemys.node.Node`. ``hz`` and ``bw`` subscribe raw and never
deserialize (ROS 1 deserializes every message just to count it); ``echo`` decodes topics of types
ninjemys does not ship from the publisher's own ``message_definition``.
"""

from __future__ import annotations

import argparse
import os
import sys
import threading
from typing import Any

from ninjemys import names
from ninjemys.master.graph import GraphSnapshot, node_api
from ninjemys.tools.cli import Subcommands, entry, master, run_subcommand
from ninjemys.tools.topic_common import (
    COALESCE,
    ID,
    NAME,
    TopicToolError,
    class_for,
    compile_filter,
    field_getter,
    make_node,
    resolve_topic,
    topic_type,
    wait_for_type,
)
from ninjemys.tools.topic_pub import cmd_pub, split_pub_options
from ninjemys.tools.topic_rates import cmd_bw, cmd_delay, cmd_hz

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


# ----------------------------------------------------------------------------------- list / info


def _cmd_list(args: argparse.Namespace) -> int:
    if args.bag:
        return _list_bag(args.bag)
    if args.subscribers_only and args.publishers_only:
        raise TopicToolError("cannot specify both subscribers- and publishers-only")
    state = GraphSnapshot.fetch(master(ID))
    pubs = [(t, state.type_of(t), n) for t, n in state.publishers.items()]
    subs = [(t, state.type_of(t), n) for t, n in state.subscribers.items()]
    if args.namespace:
        topic = resolve_topic(args.namespace)
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

    hosts: set[str] = set()
    for _, _, nodes in entries:
        for node in nodes:
            if node not in cache:
                cache[node] = node_api(client, node)
            uri = cache[node]
            if uri:
                hosts.add(urlparse(uri).hostname or "")
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
    state = GraphSnapshot.fetch(client)
    pubs: list[str] = list(state.publishers.get(topic, ()))
    subs: list[str] = list(state.subscribers.get(topic, ()))
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
    print(info_text(resolve_topic(args.topic), master(ID)))
    return 0


# ------------------------------------------------------------------------------- type / find


def _cmd_type(args: argparse.Namespace) -> int:
    from ninjemys.idl.loader import get_message_class

    topic = resolve_topic(args.topic)
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


# ------------------------------------------------------------------------------------------ echo


def _cmd_echo(args: argparse.Namespace) -> int:
    from ninjemys.tools.echo_format import EchoPrinter

    topic = resolve_topic(args.topic)
    if args.bag:
        return _echo_bag(args, topic)
    client = master(ID)
    ttype, real, field = wait_for_type(client, topic)
    printer = EchoPrinter(
        plot=args.plot,
        clear=args.clear,
        noarr=args.noarr,
        nostr=args.nostr,
        offset=args.offset_time,
        width=args.fixed_numeric_width,
    )
    getter = field_getter(field)
    predicate = compile_filter(args.filter_expr)
    node = make_node()
    done = threading.Event()
    state: dict[str, Any] = {"count": 0, "cls": None}

    def on_message(raw: Any) -> None:
        # runs on the subscription's own worker thread: printing here costs no extra thread hop
        if done.is_set():
            return
        if state["cls"] is None:
            state["cls"] = class_for(ttype, raw.connection_header)
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
        node.subscriber(real, None, on_message, raw=True, queue_size=args.queue_size, coalesce=COALESCE)
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
    p.set_defaults(run=cmd_pub)
    p = sub.add("hz")
    p.add_argument("topics", nargs="+")
    p.add_argument("-w", "--window", type=int, default=-1, help="window size, in # of messages")
    p.add_argument("--filter", dest="filter_expr", help="only measure messages matching the expression")
    p.add_argument(
        "--wall-time", dest="wall_time", action="store_true", help="calculates rate using wall time"
    )
    p.add_argument("--tcpnodelay", action="store_true")
    p.set_defaults(run=cmd_hz)
    p = sub.add("bw")
    p.add_argument("topic")
    p.add_argument("-w", "--window", type=int, default=-1)
    p.set_defaults(run=cmd_bw)
    p = sub.add("delay")
    p.add_argument("topic")
    p.add_argument("-w", "--window", type=int, default=-1)
    p.add_argument("--tcpnodelay", action="store_true")
    p.set_defaults(run=cmd_delay)
    return sub.parser if sub.matched else None


def main(argv: list[str] | None = None) -> int:
    return run_subcommand(sys.argv[1:] if argv is None else argv, USAGE, _parser, split_pub_options)


console_main = entry(main)

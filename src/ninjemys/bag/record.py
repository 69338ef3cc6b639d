"""``rosbag record``: a node that subscribes raw and writes what it receives to bag files.

Messages are never deserialized: each is stored with its publisher's connection header (type, md5sum,
message_definition, callerid, latching). Between the subscriber threads and the one writer thread sits
a queue bounded in *bytes* (``-b``); when it is full the oldest queued message is dropped and counted,
the count is reported while recording and at the end. The writer makes the bag recoverable at least
once a second (see :mod:`ninjemys.bag.writer`), names it ``*.bag.active`` while recording and renames
it on close.
"""

from __future__ import annotations

import argparse
import collections
import re
import signal
import sys
import threading
import time
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from ninjemys import interrupt
from ninjemys.bag.format import DEFAULT_CHUNK_THRESHOLD
from ninjemys.bag.writer import BagWriter
from ninjemys.errors import BagError, NinjemysError
from ninjemys.interrupt import wait_event
from ninjemys.master.snapshot import GraphSnapshot


@dataclass
class RecordOptions:
    """What to record and how (the ``rosbag record`` options, parsed)."""

    topics: list[str] = field(default_factory=list)
    all: bool = False
    regex: bool = False
    exclude: str | None = None
    node: str | None = None
    output_name: str | None = None
    output_prefix: str | None = None
    split: bool = False
    split_size: int = 0
    split_duration: float = 0.0
    max_splits: int = 0
    buffsize: int = 256 * 1024 * 1024
    chunksize: int = DEFAULT_CHUNK_THRESHOLD
    limit: int = 0
    compression: str = "none"
    quiet: bool = False
    stats: float = 0.0
    repeat_latched: bool = False
    discovery_period: float = 0.5


@dataclass
class Totals:
    messages: int = 0
    bytes: int = 0
    dropped: dict[str, int] = field(default_factory=lambda: collections.defaultdict(int))

    @property
    def dropped_total(self) -> int:
        return sum(self.dropped.values())


class ByteBoundedQueue:
    """FIFO bounded by total payload bytes; a put that overflows drops the oldest entries (counted)."""

    def __init__(self, max_bytes: int, on_drop: Callable[[str], None]) -> None:
        self.max_bytes = max_bytes
        self._items: collections.deque[tuple[str, Mapping[str, str], bytes, int]] = collections.deque()
        self._bytes = 0
        self._cond = threading.Condition()
        self._on_drop = on_drop

    def put(self, topic: str, header: Mapping[str, str], data: bytes, ns: int) -> None:
        with self._cond:
            self._items.append((topic, header, data, ns))
            self._bytes += len(data)
            while self.max_bytes and self._bytes > self.max_bytes and len(self._items) > 1:
                old = self._items.popleft()
                self._bytes -= len(old[2])
                self._on_drop(old[0])
            self._cond.notify()

    def get(self, timeout: float) -> tuple[str, Mapping[str, str], bytes, int] | None:
        with self._cond:
            if not self._items:
                self._cond.wait(timeout)
                if not self._items:
                    return None
            item = self._items.popleft()
            self._bytes -= len(item[2])
            return item

    def wake(self) -> None:
        with self._cond:
            self._cond.notify_all()

    def __len__(self) -> int:
        return len(self._items)

    @property
    def bytes(self) -> int:
        return self._bytes


def parse_duration(text: str) -> float:
    """``30``, ``30s``, ``5m``, ``2h`` -> seconds (ROS 1's --duration syntax)."""
    match = re.fullmatch(r"\s*(\d+(?:\.\d*)?)\s*([smh]?)\s*", text)
    if not match:
        raise BagError(f"invalid duration {text!r} (expected e.g. 30, 30s, 5m, 2h)")
    return float(match.group(1)) * {"": 1, "s": 1, "m": 60, "h": 3600}[match.group(2)]


def _stamp_name() -> str:
    return time.strftime("%Y-%m-%d-%H-%M-%S", time.localtime())


class BagNamer:
    """The file names ROS 1 uses: -O NAME, -o PREFIX_STAMP, or STAMP; ``_N`` per split."""

    def __init__(self, options: RecordOptions) -> None:
        if options.output_name:
            base = options.output_name
            base = base[:-4] if base.endswith(".bag") else base
        else:
            stamp = _stamp_name()
            prefix = options.output_prefix
            if prefix:
                prefix = prefix[:-4] if prefix.endswith(".bag") else prefix
                base = stamp if prefix.endswith("/") else f"{prefix}_{stamp}"
                if prefix.endswith("/"):
                    base = prefix + stamp
            else:
                base = stamp
        self.base = base
        self.split = options.split
        self.index = 0

    def next(self) -> Path:
        name = f"{self.base}_{self.index}.bag" if self.split else f"{self.base}.bag"
        self.index += 1
        return Path(name)


class Recorder:
    """Subscribes and records until :meth:`stop`; usable from tests without the command line."""

    def __init__(self, node: Any, options: RecordOptions, log: Callable[[str], None] | None = None) -> None:
        self.node = node
        self.options = options
        self.totals = Totals()
        self.log = log or (lambda text: None)
        self.namer = BagNamer(options)
        self.paths: list[Path] = []
        self.queue = ByteBoundedQueue(options.buffsize, self._dropped)
        self._exclude = re.compile(options.exclude) if options.exclude else None
        self._patterns = [re.compile(t) for t in options.topics] if options.regex else []
        self._subscribed: dict[str, Any] = {}
        self._counts: collections.Counter[str] = collections.Counter()
        self._conn_ids: dict[int, tuple[Mapping[str, str], int]] = {}
        self._latched: dict[int, tuple[str, Mapping[str, str], bytes, int]] = {}
        self._writer: BagWriter | None = None
        self._bag_started = 0.0
        self._stop = interrupt.Event()
        self._done = threading.Event()
        self._last_drop_warning = 0.0
        self._lock = threading.Lock()
        self._clock_ns = self._make_clock()
        self._writer_error: BaseException | None = None

    def _make_clock(self) -> Callable[[], int]:
        try:
            from ninjemys.node.clock import for_node

            clock = for_node(self.node)
            return clock.now_ns
        except (NinjemysError, ImportError, AttributeError):
            return time.time_ns

    # -- subscriptions ---------------------------------------------------------------------------

    def start(self) -> None:
        if not (self.options.all or self.options.regex or self.options.node):
            for topic in self.options.topics:
                self._subscribe(self.node.resolve_name(topic))
        else:
            self._discover()
        self._threads = [threading.Thread(target=self._write_loop, name="rosbag-record-writer", daemon=True)]
        if self.options.all or self.options.regex or self.options.node:
            self._threads.append(
                threading.Thread(target=self._discovery_loop, name="rosbag-record-discovery", daemon=True)
            )
        for thread in self._threads:
            thread.start()

    def _wanted(self, topic: str) -> bool:
        if self._exclude is not None and self._exclude.search(topic):
            return False
        if self.options.all or self.options.node:
            return True  # with --node, discovery already lists only that node's subscriptions
        if self._patterns:
            return any(p.fullmatch(topic) for p in self._patterns)
        return topic in {self.node.resolve_name(t) for t in self.options.topics}

    def _discover(self) -> None:
        try:
            if self.options.node:
                node_name = self.node.resolve_name(self.options.node)
                topics = GraphSnapshot.fetch(self.node.master, with_types=False).topics_of(node_name)[1]
            else:
                topics = [t for t, _type in self.node.master.get_published_topics()]
        except NinjemysError as exc:
            self.log(f"[WARN] cannot list topics from the master: {exc}")
            return
        for topic in sorted(topics):
            if topic not in self._subscribed and self._wanted(topic):
                self._subscribe(topic)

    def _discovery_loop(self) -> None:
        while not self._stop.wait(self.options.discovery_period):
            self._discover()

    def _subscribe(self, topic: str) -> None:
        if topic in self._subscribed or self._stop.is_set():
            return
        self.log(f"Subscribing to {topic}")

        def on_message(raw: Any, topic: str = topic) -> None:
            self.queue.put(topic, raw.connection_header, raw.data, self._clock_ns())

        self._subscribed[topic] = self.node.subscriber(topic, None, on_message, raw=True)

    def _dropped(self, topic: str) -> None:
        self.totals.dropped[topic] += 1
        now = time.monotonic()
        if now - self._last_drop_warning >= 1.0:
            self._last_drop_warning = now
            self.log(
                f"[WARN] rosbag record buffer exceeded. Dropping oldest queued message "
                f"({self.totals.dropped_total} dropped so far)."
            )

    # -- writing ---------------------------------------------------------------------------------

    def _open_writer(self) -> BagWriter:
        path = self.namer.next()
        writer = BagWriter(
            path,
            compression=self.options.compression,
            chunk_threshold=self.options.chunksize,
            flush_interval=1.0,
            active=True,
        )
        self.paths.append(path)
        self._conn_ids = {}
        self._bag_started = time.monotonic()
        self.log(f"Recording to '{path}'.")
        return writer

    def _write_loop(self) -> None:
        try:
            self._write_loop_inner()
        except BaseException as exc:  # reported by stop(); the recording must still close cleanly
            self._writer_error = exc
            self._stop.set()
        finally:
            if self._writer is not None:
                try:
                    self._writer.close()
                except BagError as exc:
                    self._writer_error = self._writer_error or exc
            self._done.set()

    def _write_loop_inner(self) -> None:
        opts = self.options
        last_stats = time.monotonic()
        while True:
            item = self.queue.get(0.2)
            if item is None:
                if self._stop.is_set():
                    return
                if self._writer is not None:
                    self._writer.maybe_flush()
                continue
            topic, header, data, ns = item
            if opts.limit and self._counts[topic] >= opts.limit:
                continue
            writer = self._writer
            if writer is None:
                writer = self._writer = self._open_writer()
                if opts.repeat_latched:
                    for l_topic, l_header, l_data, l_ns in list(self._latched.values()):
                        writer.write(self._connection(writer, l_topic, l_header), l_ns, l_data)
            writer.write(self._connection(writer, topic, header), ns, data)
            if opts.repeat_latched and header.get("latching") == "1":
                self._latched[id(header)] = (topic, header, data, ns)
            self._counts[topic] += 1
            self.totals.messages += 1
            self.totals.bytes += len(data)
            if opts.limit and self._counts[topic] >= opts.limit:
                self._limit_reached(topic)
            if opts.split and (
                (opts.split_size and writer.size >= opts.split_size)
                or (opts.split_duration and time.monotonic() - self._bag_started >= opts.split_duration)
            ):
                writer.close()
                self._writer = None
                if opts.max_splits and len(self.paths) > opts.max_splits:
                    oldest = self.paths.pop(0)
                    oldest.unlink(missing_ok=True)
            if opts.stats and time.monotonic() - last_stats >= opts.stats:
                last_stats = time.monotonic()
                self.log(self.summary())

    def _connection(self, writer: BagWriter, topic: str, header: Mapping[str, str]) -> int:
        """The bag connection for one publisher's header (looked up by identity: one dict per link)."""
        key = id(header)
        known = self._conn_ids.get(key)
        if known is None or known[0] is not header:
            fields = {k: v.encode() for k, v in header.items() if k not in ("topic", "tcp_nodelay")}
            known = (header, writer.connection(topic, fields))
            self._conn_ids[key] = known
        return known[1]

    def _limit_reached(self, topic: str) -> None:
        sub = self._subscribed.get(topic)
        if sub is not None:
            sub.unregister()
        fixed = not (self.options.all or self.options.regex or self.options.node)
        if fixed and all(
            self._counts[self.node.resolve_name(t)] >= self.options.limit for t in self.options.topics
        ):
            self._stop.set()

    def summary(self) -> str:
        t = self.totals
        return (
            f"Recorded {t.messages} messages ({t.bytes / 1e6:.1f} MB), dropped {t.dropped_total}, "
            f"queued {len(self.queue)} ({self.queue.bytes / 1e6:.1f} MB)"
        )

    # -- lifetime --------------------------------------------------------------------------------

    def wait(self, timeout: float | None = None) -> bool:
        """Block until recording stops by itself (limit reached) or ``timeout``; True if stopped."""
        return wait_event(self._stop, timeout)

    def request_stop(self) -> None:
        """Ask the recording to end (signal handlers and node shutdown call this); returns at once."""
        self._stop.set()

    def stop(self) -> None:
        """Stop subscribing, write what is queued, close (and rename) the bag."""
        self._stop.set()
        for sub in list(self._subscribed.values()):
            try:
                sub.unregister()
            except NinjemysError:
                pass
        self.queue.wake()
        self._done.wait()
        for thread in getattr(self, "_threads", []):
            thread.join(timeout=5.0)
        if self._writer_error is not None:
            raise BagError(f"recording failed: {self._writer_error}")


def build_parser(
    parser_class: type[argparse.ArgumentParser] = argparse.ArgumentParser,
) -> argparse.ArgumentParser:
    p = parser_class(
        prog="rosbag record",
        usage="rosbag record TOPIC1 [TOPIC2 TOPIC3 ...]",
        description="Record a bag file with the contents of specified topics.",
    )
    p.add_argument("-a", "--all", action="store_true", help="record all topics")
    p.add_argument("-e", "--regex", action="store_true", help="match topics using regular expressions")
    p.add_argument(
        "-x",
        "--exclude",
        metavar="EXCLUDE_REGEX",
        help="exclude topics matching the follow regular expression (subtracts from -a or regex)",
    )
    p.add_argument("-q", "--quiet", action="store_true", help="suppress console output")
    p.add_argument(
        "-o",
        "--output-prefix",
        metavar="PREFIX",
        help="prepend PREFIX to beginning of bag name (name will always end with date stamp)",
    )
    p.add_argument("-O", "--output-name", metavar="NAME", help="record to bag with name NAME.bag")
    p.add_argument(
        "--split", action="store_true", help="split the bag when maximum size or duration is reached"
    )
    p.add_argument(
        "--max-splits",
        type=int,
        default=0,
        help="keep a maximum of N bag files, when reaching the maximum erase the oldest one",
    )
    p.add_argument(
        "--size",
        type=int,
        default=0,
        metavar="SIZE",
        help="record a bag of maximum size SIZE MB (default: infinite)",
    )
    p.add_argument(
        "--duration",
        metavar="DURATION",
        help="record a bag of maximum duration DURATION in seconds, unless 'm', or 'h' is appended",
    )
    p.add_argument(
        "-b",
        "--buffsize",
        type=int,
        default=256,
        metavar="SIZE",
        help="use an internal buffer of SIZE MB (default: 256, 0 = infinite)",
    )
    p.add_argument(
        "--chunksize",
        type=int,
        default=768,
        metavar="SIZE",
        help="advanced. Record to chunks of SIZE KB (default: 768)",
    )
    p.add_argument(
        "-l", "--limit", type=int, default=0, metavar="NUM", help="only record NUM messages on each topic"
    )
    p.add_argument("--node", metavar="NODE", help="record all topics subscribed to by a specific node")
    p.add_argument(
        "-j",
        "--bz2",
        dest="compression",
        action="store_const",
        const="bz2",
        default="none",
        help="use BZ2 compression",
    )
    p.add_argument("--lz4", dest="compression", action="store_const", const="lz4", help="use LZ4 compression")
    p.add_argument(
        "--stats",
        type=float,
        default=0.0,
        metavar="SEC",
        help="print totals (messages, bytes, drops, queue) every SEC seconds",
    )
    p.add_argument(
        "--repeat-latched",
        action="store_true",
        help="repeat latched messages at the start of each new bag file when splitting",
    )
    p.add_argument("topics", nargs="*")
    return p


def options_from_args(args: argparse.Namespace) -> RecordOptions:
    if not args.topics and not args.all and not args.node:
        raise BagError("You must specify a topic name or else use the '-a' option.")
    if args.split and not (args.size or args.duration):
        raise BagError("--split requires --size or --duration")
    return RecordOptions(
        topics=list(args.topics),
        all=args.all,
        regex=args.regex,
        exclude=args.exclude,
        node=args.node,
        output_name=args.output_name,
        output_prefix=args.output_prefix,
        split=args.split or bool(args.size or args.duration),
        split_size=args.size * 1024 * 1024,
        split_duration=parse_duration(args.duration) if args.duration else 0.0,
        max_splits=args.max_splits,
        buffsize=args.buffsize * 1024 * 1024,
        chunksize=args.chunksize * 1024,
        limit=args.limit,
        compression=args.compression,
        quiet=args.quiet,
        stats=args.stats,
        repeat_latched=args.repeat_latched,
    )


def record_main(
    argv: list[str], parser_class: type[argparse.ArgumentParser] = argparse.ArgumentParser
) -> int:
    """Parse ``rosbag record`` arguments, record until Ctrl-C / SIGTERM / limit, close the bag."""
    from ninjemys.node import Node

    args = build_parser(parser_class).parse_intermixed_args(argv)
    options = options_from_args(args)

    def log(text: str) -> None:
        if not options.quiet:
            print(f"[ INFO] [{time.time():.6f}]: {text}", flush=True)

    node = Node("record", anonymous=True)
    recorder = Recorder(node, options, log)
    previous = {
        sig: signal.signal(sig, lambda *_: recorder.request_stop()) for sig in (signal.SIGINT, signal.SIGTERM)
    }
    node.on_shutdown(recorder.request_stop)
    try:
        recorder.start()
        recorder.wait()
    finally:
        for sig, handler in previous.items():
            signal.signal(sig, handler)
        try:
            recorder.stop()
        finally:
            node.shutdown("rosbag record finished")
    if recorder.totals.dropped_total:
        print(f"WARNING: {recorder.summary()}", file=sys.stderr)
    elif not options.quiet:
        log(recorder.summary())
    return 0

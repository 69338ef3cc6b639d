"""``rosbag play``: a node that republishes bag messages with their recorded timing.

Scheduling is absolute: message ``i`` is due at ``wall_start + (t_i - t_first) / rate`` (plus time spent
paused), measured on the monotonic clock, so sleep overshoots never accumulate over a long bag. Topics
are advertised with the bag's own type, md5sum and definition (bytes are republished untouched), and
connections recorded as latching are re-latched. ``--clock`` publishes the bag time on ``/clock`` at
``--hz`` while playing, so ``use_sim_time`` nodes follow the bag. On a terminal, space pauses and ``s``
steps one message, and ROS 1's status line shows bag time and progress.
"""

from __future__ import annotations

import argparse
import heapq
import os
import select
import signal
import struct
import sys
import time
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from typing import Any, TextIO

from ninjemys import interrupt
from ninjemys.bag.format import NSEC, Connection
from ninjemys.bag.reader import BagReader, RawMessage
from ninjemys.errors import BagError
from ninjemys.interrupt import wait_event

CLOCK_TYPE = "rosgraph_msgs/Clock"
CLOCK_MD5 = "a9c97c1d230cfc112e270351a944ee47"
CLOCK_DEFINITION = "time clock\n"
_TIME = struct.Struct("<II")


@dataclass
class PlayOptions:
    bags: list[str] = field(default_factory=list)
    rate: float = 1.0
    start: float = 0.0
    duration: float | None = None
    loop: bool = False
    clock: bool = False
    hz: float = 100.0
    delay: float = 0.2
    quiet: bool = False
    topics: list[str] | None = None
    pause: bool = False
    keep_alive: bool = False
    immediate: bool = False
    queue: int = 100
    wait_for_subscribers: bool = False
    skip_empty: float | None = None


def stand_in_class(datatype: str, md5sum: str, definition: str) -> type:
    """A class that carries only what a publisher advertises (bytes are published raw)."""
    return type(
        "BagType_" + datatype.replace("/", "_"),
        (),
        {
            "_type": datatype,
            "_md5sum": md5sum,
            "_full_text": definition,
            "_has_header": False,
            "__slots__": (),
        },
    )


class Keyboard:
    """Space / s from a terminal in cbreak mode, restored on close; inert without a terminal."""

    def __init__(self, stream: TextIO | None = None) -> None:
        self.stream = stream or sys.stdin
        self._saved: Any = None
        self.active = False
        try:
            if self.stream.isatty():
                import termios
                import tty

                fd = self.stream.fileno()
                self._saved = termios.tcgetattr(fd)
                tty.setcbreak(fd)
                self.active = True
        except (OSError, ValueError, ImportError):
            self.active = False

    def read(self) -> str | None:
        if not self.active:
            return None
        ready, _, _ = select.select([self.stream], [], [], 0)
        if not ready:
            return None
        return os.read(self.stream.fileno(), 1).decode(errors="ignore")

    def close(self) -> None:
        if self._saved is not None:
            import termios

            termios.tcsetattr(self.stream.fileno(), termios.TCSADRAIN, self._saved)
            self._saved = None


class Player:
    """Plays one or more bags through ``node``; usable from tests without the command line."""

    def __init__(
        self,
        node: Any,
        options: PlayOptions,
        out: TextIO | None = None,
        keyboard: Keyboard | None = None,
        sleep: Callable[[float], None] | None = None,
        monotonic: Callable[[], float] = time.monotonic,
    ) -> None:
        self.node = node
        self.options = options
        self.out = out or sys.stdout
        self.keyboard = keyboard
        self._monotonic = monotonic
        self._stop = interrupt.Event()
        self._sleep = sleep or self._interruptible_sleep
        self.readers: list[BagReader] = []
        try:
            for path in options.bags:
                self.readers.append(BagReader(path))
        except BaseException:
            self.close()
            raise
        for reader in self.readers:
            for warning in reader.warnings:
                print(f"WARNING: {warning}", file=sys.stderr)
        self.publishers: dict[str, Any] = {}
        self._publisher_types: dict[str, str] = {}
        self._clock_pub: Any = None
        self.published = 0
        self.paused = options.pause
        self._paused_since = self._monotonic() if self.paused else 0.0
        self.lateness: list[float] = []
        starts = [r.start_time for r in self.readers if r.start_time is not None]
        ends = [r.end_time for r in self.readers if r.end_time is not None]
        self.bag_start = min(starts) if starts else 0
        self.bag_end = max(ends) if ends else 0

    def _interruptible_sleep(self, seconds: float) -> None:
        if seconds > 0:
            self._stop.wait(seconds)

    def stop(self) -> None:
        self._stop.set()

    # -- publishers ------------------------------------------------------------------------------

    def _selected(self, conn: Connection) -> bool:
        return self.options.topics is None or conn.topic in self.options.topics

    def advertise(self) -> None:
        for reader in self.readers:
            for conn in sorted(reader.connections.values(), key=lambda c: c.id):
                if not self._selected(conn) or conn.topic in self.publishers:
                    if (
                        conn.topic in self._publisher_types
                        and self._publisher_types[conn.topic] != conn.md5sum
                    ):
                        print(
                            f"WARNING: {conn.topic} holds several types; playing only {self._publisher_types[conn.topic]}",
                            file=sys.stderr,
                        )
                    continue
                cls = stand_in_class(conn.datatype, conn.md5sum, conn.msg_def)
                self.publishers[conn.topic] = self.node.publisher(
                    conn.topic, cls, queue_size=self.options.queue, latch=conn.latching
                )
                self._publisher_types[conn.topic] = conn.md5sum
        if self.options.clock:
            self._clock_pub = self.node.publisher(
                "/clock", stand_in_class(CLOCK_TYPE, CLOCK_MD5, CLOCK_DEFINITION), queue_size=1
            )

    def _messages(self) -> Iterator[RawMessage]:
        lo = self.bag_start + int(self.options.start * NSEC)
        hi = None if self.options.duration is None else lo + int(self.options.duration * NSEC)
        streams = [r.read(self.options.topics, lo, hi) for r in self.readers]
        if len(streams) == 1:
            return streams[0]
        return heapq.merge(*streams, key=lambda m: m.time)

    # -- playing ---------------------------------------------------------------------------------

    def publish_clock(self, bag_ns: int) -> None:
        if self._clock_pub is not None:
            self._clock_pub.publish_raw(_TIME.pack(*divmod(bag_ns, NSEC)))

    def run(self) -> None:
        """Play (looping if asked) until the bag ends or :meth:`stop`."""
        self.advertise()
        if self.options.wait_for_subscribers:
            while not self._stop.is_set() and not all(
                p.get_num_connections() for p in self.publishers.values()
            ):
                self._stop.wait(0.1)
        if self.options.delay > 0:
            self._hold_clock(self.options.delay)
        while not self._stop.is_set():
            self._play_once()
            if not self.options.loop:
                break
        if not self.options.quiet:
            self.out.write("\nDone.\n")
            self.out.flush()

    def _hold_clock(self, seconds: float) -> None:
        """Sleep ``seconds``; with --clock keep /clock at the bag's start meanwhile, so sim-time nodes
        already have the bag's time when the first message arrives."""
        if self._clock_pub is None:
            self._sleep(seconds)
            return
        start = self.bag_start + int(self.options.start * NSEC)
        period = 1.0 / self.options.hz
        end = self._monotonic() + seconds
        while not self._stop.is_set():
            self.publish_clock(start)
            left = end - self._monotonic()
            if left <= 0:
                break
            self._sleep(min(period, left))

    def _play_once(self) -> None:
        opts = self.options
        rate = opts.rate if opts.rate > 0 else 1.0
        first: int | None = None
        wall0 = 0.0
        paused_total = 0.0
        last_status = 0.0
        last_clock = 0.0
        clock_period = 1.0 / opts.hz if opts.hz > 0 else 0.01
        total = (self.bag_end - self.bag_start) / NSEC
        for msg in self._messages():
            if self._stop.is_set():
                return
            if first is None:
                first = msg.time
                wall0 = self._monotonic()
            # wait for the message's slot, publishing /clock, handling keys and showing status meanwhile
            step = False
            while not opts.immediate:
                key = self.keyboard.read() if self.keyboard else None
                if key == " ":
                    self.paused = not self.paused
                    if self.paused:
                        self._paused_since = self._monotonic()
                    else:
                        paused_total += self._monotonic() - self._paused_since
                elif key == "s" and self.paused:
                    step = True
                now = self._monotonic()
                if self.paused:
                    if step:
                        # a step moves the schedule so the stepped message is due now
                        paused_total += now - self._paused_since
                        self._paused_since = now
                        wall0 = now - paused_total - (msg.time - first) / NSEC / rate
                        break
                    last_status = self._status(msg.time, total, now, last_status, True)
                    self._sleep(0.05)
                    continue
                due = wall0 + paused_total + (msg.time - first) / NSEC / rate
                if now >= due:
                    break
                if self._clock_pub is not None and now - last_clock >= clock_period:
                    last_clock = now
                    self.publish_clock(first + int((now - wall0 - paused_total) * rate * NSEC))
                last_status = self._status(msg.time, total, now, last_status, False)
                wait = due - now
                if self._clock_pub is not None:
                    wait = min(wait, max(clock_period - (now - last_clock), 0.0))
                if self.keyboard is not None and self.keyboard.active:
                    wait = min(wait, 0.05)
                self._sleep(wait)
                if self._stop.is_set():
                    return
            if self._clock_pub is not None:
                last_clock = self._monotonic()
                self.publish_clock(msg.time)
            if not opts.immediate and first is not None:
                due = wall0 + paused_total + (msg.time - first) / NSEC / rate
                self.lateness.append(self._monotonic() - due)
            pub = self.publishers.get(msg.connection.topic)
            if pub is not None and self._publisher_types.get(msg.connection.topic) == msg.connection.md5sum:
                pub.publish_raw(msg.data)
                self.published += 1
            last_status = self._status(msg.time, total, self._monotonic(), last_status, self.paused)

    def _status(self, bag_ns: int, total: float, now: float, last: float, paused: bool) -> float:
        if self.options.quiet or now - last < 0.1:
            return last
        state = " [PAUSED ] " if paused else " [RUNNING] "
        elapsed = (bag_ns - self.bag_start) / NSEC
        self.out.write(
            "\r%s Bag Time: %13.6f   Duration: %.6f / %.6f               \r"
            % (state, bag_ns / NSEC, elapsed, total)
        )
        self.out.flush()
        return now

    def keep_alive(self) -> None:
        """``-k``: stay up after the bag ends (latched topics keep serving) until stopped."""
        wait_event(self._stop)

    def close(self) -> None:
        for reader in self.readers:
            reader.close()


def build_parser(
    parser_class: type[argparse.ArgumentParser] = argparse.ArgumentParser,
) -> argparse.ArgumentParser:
    p = parser_class(
        prog="rosbag play",
        usage="rosbag play BAGFILE1 [BAGFILE2 BAGFILE3 ...]",
        description="Play back the contents of one or more bag files in a time-synchronized fashion.",
    )
    p.add_argument("-q", "--quiet", action="store_true", help="suppress console output")
    p.add_argument("-i", "--immediate", action="store_true", help="play back all messages without waiting")
    p.add_argument("--pause", action="store_true", help="start in paused mode")
    p.add_argument(
        "--queue",
        type=int,
        default=100,
        metavar="SIZE",
        help="use an outgoing queue of size SIZE (defaults to 100)",
    )
    p.add_argument("--clock", action="store_true", help="publish the clock time")
    p.add_argument(
        "--hz",
        type=float,
        default=100.0,
        help="use a frequency of HZ when publishing clock time (default: 100)",
    )
    p.add_argument(
        "-d",
        "--delay",
        type=float,
        default=0.2,
        metavar="SEC",
        help="sleep SEC seconds after every advertise call (to allow subscribers to connect)",
    )
    p.add_argument(
        "-r", "--rate", type=float, default=1.0, metavar="FACTOR", help="multiply the publish rate by FACTOR"
    )
    p.add_argument(
        "-s", "--start", type=float, default=0.0, metavar="SEC", help="start SEC seconds into the bag files"
    )
    p.add_argument(
        "-u",
        "--duration",
        type=float,
        default=None,
        metavar="SEC",
        help="play only SEC seconds from the bag files",
    )
    p.add_argument("-l", "--loop", action="store_true", help="loop playback")
    p.add_argument(
        "-k",
        "--keep-alive",
        action="store_true",
        help="keep alive past end of bag (useful for publishing latched topics)",
    )
    p.add_argument(
        "--wait-for-subscribers",
        action="store_true",
        help="wait for at least one subscriber on each topic before publishing",
    )
    p.add_argument("--topics", nargs="+", metavar="TOPIC", help="topics to play back")
    p.add_argument("bags", nargs="*")
    return p


def options_from_args(args: argparse.Namespace) -> PlayOptions:
    if not args.bags:
        raise BagError("You must specify at least 1 bag file to play back.")
    if args.rate <= 0:
        raise BagError(f"invalid rate {args.rate}: must be positive")
    if args.clock and args.hz <= 0:
        raise BagError(f"invalid --hz {args.hz}: must be positive")
    return PlayOptions(
        bags=list(args.bags),
        rate=args.rate,
        start=args.start,
        duration=args.duration,
        loop=args.loop,
        clock=args.clock,
        hz=args.hz,
        delay=args.delay,
        quiet=args.quiet,
        topics=args.topics,
        pause=args.pause,
        keep_alive=args.keep_alive,
        immediate=args.immediate,
        queue=args.queue,
        wait_for_subscribers=args.wait_for_subscribers,
    )


def play_main(argv: list[str], parser_class: type[argparse.ArgumentParser] = argparse.ArgumentParser) -> int:
    """Parse ``rosbag play`` arguments and play until the end (or Ctrl-C)."""
    from ninjemys.node import Node

    options = options_from_args(build_parser(parser_class).parse_intermixed_args(argv))
    # open the bags before joining the graph: a bad file is reported without touching the master
    player = Player(None, options)
    try:
        node = Node("play", anonymous=True)
    except BaseException:
        player.close()
        raise
    player.node = node
    keyboard = None if options.quiet else Keyboard()
    player.keyboard = keyboard
    try:
        previous = {
            sig: signal.signal(sig, lambda *_: player.stop()) for sig in (signal.SIGINT, signal.SIGTERM)
        }
        node.on_shutdown(player.stop)
        try:
            if not options.quiet:
                print(f"[ INFO] [{time.time():.6f}]: Opening {' '.join(options.bags)}", flush=True)
                print("\nHit space to toggle paused, or 's' to step.", flush=True)
            player.run()
            if options.keep_alive:
                player.keep_alive()
        finally:
            for sig, handler in previous.items():
                signal.signal(sig, handler)
    finally:
        if keyboard is not None:
            keyboard.close()
        player.close()
        node.shutdown("rosbag play finished")
    return 0

"""message_filters' core: filters that take messages in and pass them on by a policy.

The classes and their behaviour are ROS 1's Python ``message_filters`` (SimpleFilter's
``registerCallback``/``signalMessage`` protocol, Cache, TimeSynchronizer, ApproximateTimeSynchronizer
with ``allow_headerless`` and ``reset``), plus ``Chain`` from the C++ API. Stamps are handled as
integer nanoseconds internally, so matching costs integer arithmetic instead of Time/Duration
objects; the matching rules (slop inclusive per candidate, strict across a set; candidates tried
nearest first; the first complete set wins) are exactly ROS 1's.

``Subscriber`` here wraps a :class:`ninjemys.node.Node` subscription; the ``message_filters``
facade's Subscriber wraps a ``rospy.Subscriber`` instead. Both subscribe through
:func:`shared_subscriber`: all message_filters Subscribers of one node are read and called back by
one thread, so the messages a synchronizer waits for, which arrive together, cost one wake-up of
that thread instead of one per topic (ROS 1's rospy wakes a thread per connection; that wake-up,
not the matching, is most of a synchronizing node's CPU).
"""

from __future__ import annotations

import itertools
import logging
import threading
import weakref
from collections.abc import Callable, Sequence
from typing import Any

from ninjemys.rostime import Time, get_clock

_log = logging.getLogger("message_filters")
_NS = 1_000_000_000

_HEADERLESS = (
    "Cannot use message filters with non-stamped messages. Use the 'allow_headerless' constructor "
    "option to auto-assign ROS time to headerless messages."
)

__all__ = [
    "ApproximateTimeSynchronizer",
    "Cache",
    "Chain",
    "SimpleFilter",
    "Subscriber",
    "TimeSynchronizer",
    "shared_subscriber",
]


def _now_ns() -> int:
    """``Time.now()`` in nanoseconds, without making a Time (this runs for every synchronized message)."""
    secs, nsecs = get_clock()()
    return secs * _NS + nsecs


def _stamp_ns(msg: Any) -> int | None:
    """The message's header stamp in nanoseconds, or None when it has no header stamp."""
    header = getattr(msg, "header", None)
    stamp = getattr(header, "stamp", None)
    if stamp is None:
        return None
    try:
        return stamp.secs * _NS + stamp.nsecs
    except AttributeError:  # a bare number of seconds, as the mock messages of ROS 1's own tests carry
        return round(stamp * _NS)


def _to_ns(t: Any) -> int:
    return t.secs * _NS + t.nsecs


#: per node, the subscription whose thread its message_filters Subscribers share
_hosts: weakref.WeakKeyDictionary[Any, Any] = weakref.WeakKeyDictionary()
_hosts_lock = threading.Lock()


def shared_subscriber(node: Any, topic: str, msg_class: Any, callback: Any, **kwargs: Any) -> Any:
    """``node.subscriber(topic, msg_class, callback, **kwargs)`` on the thread every message_filters
    Subscriber of ``node`` shares (the first one's, while it is open; else this one starts a new one).
    Their callbacks then run one after another, as under roscpp's single spinner."""
    with _hosts_lock:
        host = _hosts.get(node)
        if host is not None and host.closed:
            host = None
        handle = node.subscriber(topic, msg_class, callback, share_thread=host, **kwargs)
        if host is None:
            _hosts[node] = handle
    return handle


def _pass_on(source: SimpleFilter, msg: Any) -> None:
    """``source.signalMessage(msg)`` for a source filter, per received message: with one connected
    filter (a synchronizer input) that filter is called directly."""
    callbacks = source.callbacks
    if len(callbacks) == 1:
        ((cb, args),) = callbacks.values()  # taken out first: the call may register more
        cb(msg, *args)
    else:
        source.signalMessage(msg)


class SimpleFilter:
    """The output side every filter shares: callbacks registered in order, called with the outputs."""

    def __init__(self) -> None:
        self.callbacks: dict[int, tuple[Callable[..., Any], tuple[Any, ...]]] = {}

    def registerCallback(self, cb: Callable[..., Any], *args: Any) -> int:  # noqa: N802 - ROS 1 API
        """Call ``cb(*outputs, *args)`` whenever this filter has output; returns a connection id."""
        conn = max(self.callbacks, default=-1) + 1
        self.callbacks[conn] = (cb, args)
        return conn

    def signalMessage(self, *msg: Any) -> None:  # noqa: N802 - ROS 1 API
        for cb, args in list(self.callbacks.values()):
            cb(*(msg + args))


class Subscriber(SimpleFilter):
    """A source filter: every message of a Node subscription is passed on (on the node's shared
    message_filters thread, see :func:`shared_subscriber`)."""

    def __init__(self, node: Any, topic: str, msg_class: Any, **kwargs: Any) -> None:
        super().__init__()
        self.topic = topic
        self.sub = shared_subscriber(node, topic, msg_class, self.callback, **kwargs)

    def callback(self, msg: Any) -> None:
        _pass_on(self, msg)

    def getTopic(self) -> str:  # noqa: N802 - ROS 1 API
        return self.topic

    def unregister(self) -> None:
        self.sub.unregister()

    def __getattr__(self, key: str) -> Any:
        if key == "sub":
            raise AttributeError(key)
        return getattr(self.sub, key)


class Cache(SimpleFilter):
    """The last ``cache_size`` messages with their stamps, queried by time; passes every message on."""

    def __init__(self, f: SimpleFilter, cache_size: int = 1, allow_headerless: bool = False) -> None:
        super().__init__()
        self.cache_size = cache_size
        self.cache_msgs: list[Any] = []
        self.cache_times: list[Any] = []
        self.allow_headerless = allow_headerless
        self._lock = threading.Lock()
        self.connectInput(f)

    def connectInput(self, f: SimpleFilter) -> None:  # noqa: N802 - ROS 1 API
        self.incoming_connection = f.registerCallback(self.add)

    def add(self, msg: Any) -> None:
        header = getattr(msg, "header", None)
        stamp = getattr(header, "stamp", None)
        if stamp is None:
            if not self.allow_headerless:
                _log.warning(_HEADERLESS)
                return
            stamp = Time.now()
        with self._lock:
            self.cache_times.append(stamp)
            self.cache_msgs.append(msg)
            if len(self.cache_msgs) > self.cache_size:
                del self.cache_msgs[0]
                del self.cache_times[0]
        self.signalMessage(msg)

    def _pairs(self) -> list[tuple[Any, int]]:
        with self._lock:
            return [(m, _to_ns(t)) for m, t in zip(self.cache_msgs, self.cache_times, strict=True)]

    def getInterval(self, from_stamp: Any, to_stamp: Any) -> list[Any]:  # noqa: N802 - ROS 1 API
        """The cached messages stamped in ``[from_stamp, to_stamp]``, oldest first."""
        lo, hi = _to_ns(from_stamp), _to_ns(to_stamp)
        if lo > hi:
            raise ValueError(f"getInterval: from_stamp {from_stamp} is after to_stamp {to_stamp}")
        return [m for m, t in self._pairs() if lo <= t <= hi]

    def getElemAfterTime(self, stamp: Any) -> Any:  # noqa: N802 - ROS 1 API
        """The oldest cached message stamped at or after ``stamp`` (None if there is none)."""
        t0 = _to_ns(stamp)
        return next((m for m, t in self._pairs() if t >= t0), None)

    def getElemBeforeTime(self, stamp: Any) -> Any:  # noqa: N802 - ROS 1 API
        """The newest cached message stamped at or before ``stamp`` (None if there is none)."""
        t0 = _to_ns(stamp)
        older = [m for m, t in self._pairs() if t <= t0]
        return older[-1] if older else None

    def getLatestTime(self) -> Any:  # noqa: N802 - ROS 1 API
        with self._lock:
            return self.cache_times[-1] if self.cache_times else None

    getLastestTime = getLatestTime  # noqa: N815 - ROS 1's misspelt alias, kept for old code

    def getOldestTime(self) -> Any:  # noqa: N802 - ROS 1 API
        with self._lock:
            return self.cache_times[0] if self.cache_times else None

    def getLast(self) -> Any:  # noqa: N802 - ROS 1 API
        latest = self.getLatestTime()
        return None if latest is None else self.getElemAfterTime(latest)


class TimeSynchronizer(SimpleFilter):
    """Outputs one message per input when all inputs have a message with exactly the same stamp.

    ``queue_size`` stamps are kept per input (the oldest dropped first). With ``reset`` under
    simulated time, an input's queue is cleared when the clock jumps back (a bag loop).
    """

    def __init__(self, fs: Sequence[SimpleFilter], queue_size: int, reset: bool = False) -> None:
        super().__init__()
        self.queue_size = queue_size
        self.lock = threading.Lock()
        self.enable_reset = reset
        self.connectInput(fs)

    def connectInput(self, fs: Sequence[SimpleFilter]) -> None:  # noqa: N802 - ROS 1 API
        self.queues: list[dict[int, Any]] = [{} for _ in fs]
        self.latest_stamps = [0 for _ in fs]
        self.input_connections = [
            f.registerCallback(self.add, q, i) for i, (f, q) in enumerate(zip(fs, self.queues, strict=True))
        ]

    def _reset_check(self, my_queue: dict[int, Any], index: int | None) -> int | None:
        """Jump-back handling of ``reset=True``; returns the clock reading, or None without reset."""
        if not self.enable_reset or index is None:
            return None
        now = _now_ns()
        if now < self.latest_stamps[index]:
            _log.debug("Detected jump back in time. Clearing message filter queue")
            my_queue.clear()
        self.latest_stamps[index] = now
        return now

    def add(self, msg: Any, my_queue: dict[int, Any], my_queue_index: int | None = None) -> None:
        stamp = _stamp_ns(msg)
        if stamp is None:
            _log.warning(_HEADERLESS)
            return
        with self.lock:
            now = self._reset_check(my_queue, my_queue_index)
            my_queue[stamp] = msg
            while len(my_queue) > self.queue_size:
                del my_queue[min(my_queue)]
            if now is not None and max(self.latest_stamps) != now:
                return
            common = set(self.queues[0]).intersection(*self.queues[1:])
            for t in sorted(common):
                self.signalMessage(*[q.pop(t) for q in self.queues])


class ApproximateTimeSynchronizer(TimeSynchronizer):
    """Outputs one message per input when their stamps lie within ``slop`` seconds of each other.

    ROS 1's Python policy: when a message arrives, every other input's stamps within ``slop`` of it
    are candidates, nearest first; the first combination (in that order) whose spread is below
    ``slop`` is output and removed. ``allow_headerless`` stamps header-less messages with the
    current ROS time. A clock jump back clears all queues.
    """

    def __init__(
        self,
        fs: Sequence[SimpleFilter],
        queue_size: int,
        slop: float,
        allow_headerless: bool = False,
        reset: bool = False,
    ) -> None:
        super().__init__(fs, queue_size, reset=reset)
        self.slop = slop
        self._slop_ns = round(slop * _NS)
        self.allow_headerless = allow_headerless
        self._last_added = 0

    def connectInput(self, fs: Sequence[SimpleFilter]) -> None:  # noqa: N802 - ROS 1 API
        super().connectInput(fs)
        queues = self.queues
        #: per input, the other inputs' queues (what a message from that input is matched against)
        self._others = [queues[:i] + queues[i + 1 :] for i in range(len(queues))]

    def add(self, msg: Any, my_queue: dict[int, Any], my_queue_index: int | None = None) -> None:
        """Match ``msg`` (from input ``my_queue_index``) against the other inputs; this runs for every
        message of every input, so the common case is written out (no Time objects, no helpers)."""
        header = getattr(msg, "header", None)
        stamp = getattr(header, "stamp", None)
        if stamp is None:
            if not self.allow_headerless:
                _log.warning(_HEADERLESS)
                return
            stamp = _now_ns()
        else:
            stamp = stamp.secs * _NS + stamp.nsecs
        slop = self._slop_ns
        with self.lock:
            reset_now = self._reset_check(my_queue, my_queue_index) if self.enable_reset else None
            my_queue[stamp] = msg
            secs, nsecs = get_clock()()
            now = secs * _NS + nsecs
            if now < self._last_added:
                _log.info("ApproximateTimeSynchronizer: Detected jump back in time. Clearing buffer.")
                for q in self.queues:
                    q.clear()
            self._last_added = now
            while len(my_queue) > self.queue_size:
                del my_queue[min(my_queue)]
            if reset_now is not None and max(self.latest_stamps) != reset_now:
                return
            queues = self.queues
            others = queues if my_queue_index is None else self._others[my_queue_index]
            candidates: list[list[int]] = []
            for queue in others:
                near = [(d if d >= 0 else -d, s) for s in queue for d in (s - stamp,) if -slop <= d <= slop]
                if not near:
                    return
                if len(near) > 1:
                    near.sort(key=_first)  # stable: equal distances keep arrival order, as ROS 1
                candidates.append([s for _d, s in near])
            for combo in itertools.product(*candidates):
                if my_queue_index is None:
                    stamps = combo
                else:
                    stamps = (*combo[:my_queue_index], stamp, *combo[my_queue_index:])
                if max(stamps) - min(stamps) < slop and all(
                    t in q for q, t in zip(queues, stamps, strict=True)
                ):
                    self.signalMessage(*[q.pop(t) for q, t in zip(queues, stamps, strict=True)])
                    break


def _first(pair: tuple[int, int]) -> int:
    return pair[0]


class Chain(SimpleFilter):
    """Filters in series (C++ ``message_filters::Chain``): input goes to the first, output comes from the last.

    ``addFilter(f)`` connects ``f``'s input (its ``connectInput``) to the previous stage's output.
    """

    def __init__(self, f: SimpleFilter | None = None) -> None:
        super().__init__()
        self._input = SimpleFilter()
        self._filters: list[Any] = []
        self._out_conn: tuple[SimpleFilter, int] | None = None
        if f is not None:
            self.connectInput(f)

    def connectInput(self, f: SimpleFilter) -> None:  # noqa: N802 - C++ API
        f.registerCallback(self.add)

    def add(self, *msg: Any) -> None:
        self._input.signalMessage(*msg)

    def addFilter(self, flt: Any) -> Any:  # noqa: N802 - C++ API
        """Append ``flt`` (anything with ``connectInput`` and ``registerCallback``); returns it."""
        upstream = self._filters[-1] if self._filters else self._input
        if self._out_conn is not None:
            source, conn = self._out_conn
            source.callbacks.pop(conn, None)
        flt.connectInput(upstream)
        self._filters.append(flt)
        self._out_conn = (flt, flt.registerCallback(self.signalMessage))
        return flt

    def getFilter(self, index: int) -> Any:  # noqa: N802 - C++ API
        return self._filters[index]

"""rostopic's Python API as ROS 1 programs and test harnesses import it: a topic's type and class
(``get_topic_class("/odom/pose")`` included, with the function that extracts the field), the rate,
bandwidth and delay meters ``rostopic hz/bw/delay`` are built from, topic listings and info text.

It sits on the rosgraph and rospy facades (the ``rostopic`` command is ninjemys.tools.rostopic; the
layering keeps facades below the tools, so the two share the master API, not code).
"""

from __future__ import annotations

import itertools
import sys
import threading
import time
from collections.abc import Callable, Sequence
from io import StringIO
from typing import Any

import rosgraph
import rosgraph.names
import rospy
from ninjemys.master.snapshot import GraphSnapshot
from ninjemys.node.rates import (
    BandwidthWindow,
    DelayWindow,
    RateWindow,
    bw_text,
    delay_text,
    hz_table,
    hz_text,
)
from roslib.message import get_message_class

__all__ = [
    "ROSTopicException",
    "ROSTopicIOException",
    "ROSTopicHz",
    "ROSTopicDelay",
    "ROSTopicBandwidth",
    "msgevalgen",
    "get_topic_type",
    "get_topic_class",
    "get_topic_list",
    "get_info_text",
    "get_api",
    "find_by_type",
    "create_publisher",
    "publish_message",
    "NAME",
    "SUBSCRIBER_TIMEOUT",
    "rostopicmain",
]

NAME = "rostopic"
_CALLER = "/rostopic"
#: seconds ``rostopic pub --once`` waits for a subscriber
SUBSCRIBER_TIMEOUT = 5.0
#: seconds ``publish_message(..., once=True)`` keeps a latched message up
_ONCE_DELAY = 3.0


class ROSTopicException(Exception):
    """A rostopic operation failed (unknown topic, unloadable type ...)."""


class ROSTopicIOException(ROSTopicException):
    """The master or a node could not be reached."""


def _master() -> rosgraph.Master:
    return rosgraph.Master(_CALLER)


def _topic_types(master: rosgraph.Master) -> list[list[str]]:
    try:
        return master.getTopicTypes()
    except OSError:
        raise ROSTopicIOException("Unable to communicate with master!") from None


def _index_or_slice(text: str) -> int | slice:
    """``3`` -> 3, ``1:-1:2`` -> slice(1, -1, 2); ValueError naming the bad part."""
    if text == "":
        raise ValueError("empty array index")
    parts = text.split(":")
    if len(parts) == 1:
        try:
            return int(parts[0])
        except ValueError:
            raise ValueError(f"non-integer array index step '{parts[0]}'") from None
    if len(parts) > 3:
        raise ValueError("too many slice arguments")
    args: list[int | None] = [None, None, None]
    for i, (part, what) in enumerate(zip(parts, ("start", "stop", "step"), strict=False)):
        if part != "":
            try:
                args[i] = int(part)
            except ValueError:
                raise ValueError(f"non-integer slice {what} '{part}'") from None
    return slice(*args)


def msgevalgen(pattern: str) -> Callable[[Any], Any] | None:
    """A function taking a message to the field ``pattern`` names (``/x[2:]/y``), or None for an
    empty pattern; a malformed slice prints why on stderr and gives None, as in ROS 1."""
    evals: list[tuple[str, int | slice | None]] = []
    for f in (f for f in pattern.split("/") if f):
        if "[" not in f:
            evals.append((f, None))
            continue
        name, rest = f.split("[", 1)
        if not rest.endswith("]"):
            print(f"missing closing ']' in slice spec '{f}'", file=sys.stderr)
            return None
        try:
            evals.append((name, _index_or_slice(rest[:-1])))
        except ValueError as exc:
            print(f"field '{name}' has invalid slice argument '{rest[:-1]}': {exc}", file=sys.stderr)
            return None

    def msgeval(msg: Any, evals: list[tuple[str, int | slice | None]]) -> Any:
        for i, (name, index) in enumerate(evals):
            try:
                msg = getattr(msg, name)
            except AttributeError:
                print(f"no field named {name} in {pattern}", file=sys.stderr)
                return None
            if index is not None:
                try:
                    msg = msg[index]
                except IndexError as exc:
                    print(f"{exc}: {pattern}", file=sys.stderr)
                    return None
                if isinstance(msg, list):
                    return [msgeval(m, evals[i + 1 :]) for m in msg]
        return msg

    return (lambda msg: msgeval(msg, evals)) if evals else None


def _has_field(msg_class: Any, path: str) -> bool:
    value = msg_class()
    try:
        for attr in path.split("/"):
            value = getattr(value, attr)
    except AttributeError:
        return False
    return True


def _get_topic_type(topic: str) -> tuple[str | None, str | None, Callable[[Any], Any] | None]:
    types = _topic_types(_master())
    matches = [(t, tt) for t, tt in types if t == topic]
    if not matches:
        # a field of a topic (/odom/pose/pose): the longest topic that has that field
        matches = sorted(((t, tt) for t, tt in types if topic.startswith(t + "/")), reverse=True)
        while matches:
            t, tt = matches[0]
            cls = get_message_class(tt)
            path = topic[len(t) + 1 :].rstrip("/").split("[")[0]
            if not cls or path == "":
                break
            if _has_field(cls, path):
                matches = [(t, tt)]
                break
            matches.pop(0)
    if not matches:
        return None, None, None
    t, tt = matches[0]
    if tt == rosgraph.names.ANYTYPE:
        return None, None, None
    return tt, t, msgevalgen(topic[len(t) :])


def get_topic_type(
    topic: str, blocking: bool = False
) -> tuple[str | None, str | None, Callable[[Any], Any] | None]:
    """``(type, real topic, field extractor or None)`` of ``topic`` (which may name a field inside a
    topic); ``(None, None, None)`` if unknown, or waits for it with ``blocking``."""
    found = _get_topic_type(topic)
    if found[0] or not blocking:
        return found
    sys.stderr.write(f"WARNING: topic [{topic}] does not appear to be published yet\n")
    while not rospy.is_shutdown():
        found = _get_topic_type(topic)
        if found[0]:
            return found
        time.sleep(0.1)
    return None, None, None


def get_topic_class(
    topic: str, blocking: bool = False
) -> tuple[Any, str | None, Callable[[Any], Any] | None]:
    """Like get_topic_type, with the message class instead of the type name."""
    topic_type, real_topic, msg_eval = get_topic_type(topic, blocking=blocking)
    if topic_type is None:
        return None, None, None
    cls = get_message_class(topic_type)
    if not cls:
        raise ROSTopicException(f"Cannot load message class for [{topic_type}]. Are your messages built?")
    return cls, real_topic, msg_eval


def get_topic_list(master: rosgraph.Master | None = None) -> tuple[list[tuple[str, str, list[str]]], ...]:
    """``(publications, subscriptions)``, each ``[(topic, type, [node, ...]), ...]``."""
    master = master or _master()
    state = master.getSystemState()
    graph = GraphSnapshot.from_system_state(state, topic_types=_topic_types(master))
    return tuple(
        [(t, graph.topic_types.get(t, "unknown type"), list(nodes)) for t, nodes in table.items()]
        for table in (graph.publishers, graph.subscribers)
    )


_caller_apis: dict[str, str] = {}


def get_api(master: rosgraph.Master, caller_id: str) -> str:
    """The XML-RPC URI of node ``caller_id`` (cached), or ``unknown address NODE``."""
    api = _caller_apis.get(caller_id)
    if not api:
        try:
            api = master.lookupNode(caller_id)
            _caller_apis[caller_id] = api
        except OSError:
            raise ROSTopicIOException("Unable to communicate with master!") from None
        except rosgraph.MasterError:
            api = f"unknown address {caller_id}"
    return api


def get_info_text(topic: str) -> str:
    """What ``rostopic info TOPIC`` prints: its type, publishers and subscribers with their URIs."""
    master = _master()
    try:
        pubs, subs = get_topic_list(master=master)
    except OSError:
        raise ROSTopicIOException("Unable to communicate with master!") from None
    pubs = [x for x in pubs if x[0] == topic]
    subs = [x for x in subs if x[0] == topic]
    if not pubs and not subs:
        raise ROSTopicException(f"Unknown topic {topic}")
    buff = StringIO()
    buff.write(f"Type: {(pubs or subs)[0][1]}\n\n")
    for title, entries in (("Publishers", pubs), ("Subscribers", subs)):
        if entries:
            buff.write(f"{title}: \n")
            for node in itertools.chain(*[nodes for _t, _tt, nodes in entries]):
                buff.write(f" * {node} ({get_api(master, node)})\n")
        else:
            buff.write(f"{title}: None\n")
        buff.write("\n")
    return buff.getvalue()


def find_by_type(topic_type: str) -> list[str]:
    """The topics of type ``topic_type``."""
    return [t for t, tt in _topic_types(_master()) if tt == topic_type]


class ROSTopicHz:
    """Receives messages (``callback_hz``) and computes their rate statistics, per topic.

    ROS 1's class shape over :class:`ninjemys.node.rates.RateWindow` (one per topic; topic None is
    the single-topic state ROS 1 kept in plain attributes): the window, formulas and printed lines
    are the ``rostopic hz`` command's."""

    def __init__(
        self, window_size: int, filter_expr: Callable[[Any], bool] | None = None, use_wtime: bool = False
    ):
        self.lock = threading.Lock()
        self.filter_expr = filter_expr
        self.use_wtime = use_wtime
        self.window_size = 50000 if window_size < 0 else window_size
        self._windows: dict[Any, RateWindow] = {}

    def _window(self, topic: str | None) -> RateWindow:
        window = self._windows.get(topic)
        if window is None:
            window = self._windows[topic] = RateWindow(self.window_size)
        return window

    # ROS 1's accessors of the per-topic state
    def get_last_printed_tn(self, topic: str | None = None) -> float:
        return self._window(topic).last_reported or 0

    def set_last_printed_tn(self, value: float, topic: str | None = None) -> None:
        self._window(topic).last_reported = value

    def get_msg_t0(self, topic: str | None = None) -> float:
        first = self._window(topic).first
        return -1 if first is None else first

    def set_msg_t0(self, value: float, topic: str | None = None) -> None:
        self._window(topic).first = None if value < 0 else value

    def get_msg_tn(self, topic: str | None = None) -> float:
        return self._window(topic).last or 0

    def set_msg_tn(self, value: float, topic: str | None = None) -> None:
        self._window(topic).last = value

    def get_times(self, topic: str | None = None) -> list[float]:
        return list(self._window(topic).gaps)

    def set_times(self, value: list[float], topic: str | None = None) -> None:
        gaps = self._window(topic).gaps
        gaps.clear()
        gaps.extend(value)

    last_printed_tn = property(get_last_printed_tn, set_last_printed_tn)
    msg_t0 = property(get_msg_t0, set_msg_t0)
    msg_tn = property(get_msg_tn, set_msg_tn)
    times = property(get_times, set_times)

    def callback_hz(self, m: Any, topic: str | None = None) -> None:
        """Subscriber callback: record the arrival time (ROS time, or wall time with use_wtime)."""
        if self.filter_expr is not None and not self.filter_expr(m):
            return
        now = rospy.Time.from_sec(time.time()) if self.use_wtime else rospy.get_rostime()
        window = self._window(topic)
        if now.is_zero():
            if window.gaps:
                print("time has reset, resetting counters")
                window.reset()
            return
        window.arrived(now.to_sec())

    def get_hz(self, topic: str | None = None) -> tuple[float, float, float, float, int] | None:
        """``(rate, min_delta, max_delta, std_dev, window)``, or None without new messages."""
        return self._window(topic).report()

    def print_hz(self, topics: Sequence[str | None] = (None,)) -> None:
        """Print the rate of one topic, or a table of several, as ``rostopic hz`` does."""
        if len(topics) == 1:
            print(hz_text(self.get_hz(topics[0])))
            return
        print(hz_table([(str(t), self.get_hz(t)) for t in topics]))


class ROSTopicDelay:
    """Receives stamped messages (``callback_delay``) and computes the delay of their stamps
    (ROS 1's class shape over :class:`ninjemys.node.rates.DelayWindow`)."""

    def __init__(self, window_size: int):
        self.lock = threading.Lock()
        self.window_size = 50000 if window_size < 0 else window_size
        self._window = DelayWindow(self.window_size)

    @property
    def delays(self) -> list[float]:
        return list(self._window.delays)

    @property
    def msg_t0(self) -> float:
        return -1.0 if self._window.first is None else self._window.first

    @property
    def msg_tn(self) -> float:
        return self._window.last or 0

    def callback_delay(self, msg: Any) -> None:
        """Subscriber callback: record now minus the message's header stamp."""
        if not msg._has_header:
            rospy.logerr("msg does not have header")
            return
        now = rospy.get_rostime()
        if now.is_zero():
            if self._window.delays:
                print("time has reset, resetting counters")
                self._window.reset()
            return
        self._window.arrived(now.to_sec(), msg.header.stamp.to_sec())

    def get_delay(self) -> tuple[float, float, float, float, int] | None:
        """``(mean, min, max, std_dev, window)`` of the delays, or None without new messages."""
        return self._window.report()

    def print_delay(self) -> None:
        """Print the delay statistics as ``rostopic delay`` does."""
        if not self._window.delays:
            return
        print(delay_text(self.get_delay()))


class ROSTopicBandwidth:
    """Receives raw messages (``rospy.AnyMsg``, ``callback``) and computes the bandwidth they use
    (ROS 1's class shape over :class:`ninjemys.node.rates.BandwidthWindow`)."""

    def __init__(self, window_size: int = 100):
        self.lock = threading.Lock()
        self.window_size = window_size or 100
        self._window = BandwidthWindow(self.window_size)

    @property
    def times(self) -> list[float]:
        return [t for t, _ in list(self._window.samples)]

    @property
    def sizes(self) -> list[int]:
        return [s for _, s in list(self._window.samples)]

    @property
    def last_printed_tn(self) -> float:
        return 0

    def callback(self, data: Any) -> None:
        """Subscriber callback: record the message's wire size and arrival (wall) time."""
        self._window.arrived(time.time(), len(data._buff))

    def print_bw(self) -> None:
        """Print average bandwidth and message sizes as ``rostopic bw`` does (nothing before 2 messages)."""
        stats = self._window.report(time.time())
        if stats is not None:
            print(bw_text(stats))


def create_publisher(
    topic_name: str, topic_type: str, latch: bool, disable_rostime: bool = True
) -> tuple[Any, Any]:
    """A publisher of ``topic_type`` on ``topic_name`` (resolved as rostopic resolves it) and the
    message class, in an anonymous ``rostopic`` node started for it, as ``rostopic pub`` does."""
    topic_name = rosgraph.names.script_resolve_name("rostopic", topic_name)
    if "/" not in topic_type:  # not pkg/Type: ROS 1's class lookup raises on it
        raise ROSTopicException(f"invalid topic type: {topic_type}")
    msg_class = get_message_class(topic_type)
    if msg_class is None:
        pkg = topic_type.split("/")[0] if "/" in topic_type else None
        raise ROSTopicException(
            f"invalid message type: {topic_type}.\nIf this is a valid message type, perhaps you need to type 'rosmake {pkg}'"
        )
    rospy.init_node("rostopic", anonymous=True, disable_rosout=True, disable_rostime=disable_rostime)
    return rospy.Publisher(topic_name, msg_class, latch=latch, queue_size=100), msg_class


def _fill_message_args(msg: Any, pub_args: list[Any]) -> None:
    import genpy.message
    from std_msgs.msg import Header

    now = rospy.get_rostime()
    try:
        genpy.message.fill_message_args(msg, pub_args, keys={"now": now, "auto": Header(stamp=now)})
    except genpy.message.MessageException as e:
        raise ROSTopicException(
            f"{e}\n\nArgs are: [{genpy.message.get_printable_message_args(msg)}]"
        ) from None


def publish_message(
    pub: Any,
    msg_class: Any,
    pub_args: list[Any],
    rate: float | None = None,
    once: bool = False,
    verbose: bool = False,
    substitute_keywords: bool = False,
) -> None:
    """Fill a ``msg_class`` from YAML-parsed ``pub_args`` and publish it: latched (until shutdown,
    or ``once``), or at ``rate`` Hz (refilled each time with ``substitute_keywords``, so ``now``
    advances), as ``rostopic pub`` does."""
    import genpy

    msg = msg_class()
    _fill_message_args(msg, pub_args)
    try:
        if rate is None:
            text = f"publishing and latching [{msg}]" if verbose else "publishing and latching message"
            print(text + (f" for {_ONCE_DELAY} seconds" if once else ". Press ctrl-C to terminate"))
            try:
                pub.publish(msg)
            except TypeError as e:
                raise ROSTopicException(str(e)) from None
            if not once:
                rospy.spin()
            return
        try:
            r = rospy.Rate(float(rate))
        except ValueError:
            raise ROSTopicException("Rate must be a number") from None
        while not rospy.is_shutdown():
            if substitute_keywords:
                _fill_message_args(msg, pub_args)
            if verbose:
                print(f"publishing {msg}")
            pub.publish(msg)
            r.sleep()
    except (rospy.ROSSerializationException, genpy.SerializationError) as e:
        import rosmsg

        raise ROSTopicException(
            "Unable to publish message. One of the fields has an incorrect type:\n"
            f"  {e}\n\nmsg file:\n{rosmsg.get_msg_text(msg_class._type)}"
        ) from None


def rostopicmain(argv: list[str] | None = None) -> None:
    """The ``rostopic`` command with ``argv`` (``argv[0]`` is the program name), as ROS 1's entry point:
    our ``rostopic`` runs it; a failure exits with its status."""
    import subprocess

    from ninjemys.commands import command_path

    argv = sys.argv if argv is None else argv
    code = subprocess.call([command_path("rostopic"), *argv[1:]])
    if code:
        sys.exit(code)

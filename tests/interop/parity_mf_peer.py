"""message_filters' Cache, TimeSynchronizer and ApproximateTimeSynchronizer fed by SimpleFilters with
fixed stamps, printed as JSON (run under either interpreter, no master needed): what each query of
the cache returns and which tuples each synchronizer emits, in order."""

import json

import message_filters
import rospy
from geometry_msgs.msg import PointStamped
from std_msgs.msg import Header, String

if hasattr(rospy.rostime, "set_rostime_initialized"):
    # ROS 1's synchronizers read rospy.Time.now() (for ``reset``); without a node its clock must be
    # declared usable (it then reads wall time, which these checks never depend on)
    rospy.rostime.set_rostime_initialized(True)


def point(secs, x=0.0):
    msg = PointStamped()
    msg.header = Header(stamp=rospy.Time.from_sec(secs), frame_id="f")
    msg.point.x = x
    return msg


def label(msg):
    if msg is None:
        return None
    return round(msg.header.stamp.to_sec(), 6)


def labels(msgs):
    return [label(m) for m in msgs]


def stamp(t):
    return None if t is None else round(t.to_sec(), 6)


def cache_checks():
    out = {}
    source = message_filters.SimpleFilter()
    cache = message_filters.Cache(source, 5)
    seen = []
    cache.registerCallback(lambda m: seen.append(label(m)))
    out["empty"] = [stamp(cache.getLatestTime()), stamp(cache.getOldestTime()), label(cache.getLast())]
    for secs in (1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 2.5):
        source.signalMessage(point(secs))
    t = rospy.Time.from_sec
    out["seen"] = seen
    out["latest_oldest"] = [
        stamp(cache.getLatestTime()),
        stamp(cache.getLastestTime()),
        stamp(cache.getOldestTime()),
    ]
    out["last"] = label(cache.getLast())
    out["after"] = [label(cache.getElemAfterTime(t(x))) for x in (0.0, 3.0, 3.5, 7.0, 9.0)]
    out["before"] = [label(cache.getElemBeforeTime(t(x))) for x in (0.0, 3.0, 3.5, 7.0, 9.0)]
    out["interval"] = [labels(cache.getInterval(t(a), t(b))) for a, b in ((0, 10), (3.5, 6), (4, 4), (7, 9))]
    out["cache_size"] = [cache.cache_size, len(cache.cache_msgs), cache.allow_headerless]
    headerless = message_filters.Cache(message_filters.SimpleFilter(), 3)
    headerless.add(String("no header"))
    out["headerless_refused"] = [len(headerless.cache_msgs), len(headerless.cache_times)]
    return out


def sync_checks():
    out = {}
    a, b, c = message_filters.SimpleFilter(), message_filters.SimpleFilter(), message_filters.SimpleFilter()
    exact = message_filters.TimeSynchronizer([a, b], 3)
    got = []
    exact.registerCallback(lambda m1, m2, tag: got.append([label(m1), label(m2), tag]), "x")
    for secs in (1.0, 2.0, 3.0, 4.0, 5.0):
        a.signalMessage(point(secs))
    for secs in (0.5, 2.0, 3.0, 4.5, 5.0):
        b.signalMessage(point(secs))
    out["exact"] = got

    approx = message_filters.ApproximateTimeSynchronizer([a, b, c], 4, 0.1)
    got2 = []
    approx.registerCallback(lambda *ms: got2.append(labels(ms)))
    for secs in (10.0, 10.5, 11.0, 11.5, 12.0):
        a.signalMessage(point(secs))
        b.signalMessage(point(secs + 0.05))
        c.signalMessage(point(secs - 0.04))
    for secs in (13.0, 13.3):
        a.signalMessage(point(secs))
        b.signalMessage(point(secs + 0.25))
        c.signalMessage(point(secs))
    out["approx"] = got2
    out["approx_fields"] = [approx.queue_size, approx.slop.to_sec(), approx.allow_headerless]

    d, e = message_filters.SimpleFilter(), message_filters.SimpleFilter()
    order = message_filters.ApproximateTimeSynchronizer([d, e], 2, 0.2)
    got3 = []
    order.registerCallback(lambda *ms: got3.append(labels(ms)))
    for x, y in ((1.0, 1.1), (2.0, 1.95), (3.0, 3.3), (4.0, 3.9), (2.5, 2.6)):
        d.signalMessage(point(x))
        e.signalMessage(point(y))
    out["approx_small_queue"] = got3
    return out


print(json.dumps({"cache": cache_checks(), "sync": sync_checks()}))

"""Runs Debian's message_filters synchronizers on a recorded event list (under /usr/bin/python3).

stdin: JSON {"kind": "exact"|"approx", "queue_size": n, "slop": s, "inputs": k, "events": [[input, secs, nsecs], ...]}
stdout: JSON list of output sets, each a list of [secs, nsecs] per input.
"""

import json
import sys

import message_filters
import rospy
import rospy.rostime

rospy.rostime.set_rostime_initialized(True)


class Header:
    def __init__(self, stamp):
        self.stamp = stamp


class Msg:
    def __init__(self, secs, nsecs):
        self.header = Header(rospy.Time(secs, nsecs))


def main():
    spec = json.load(sys.stdin)
    sources = [message_filters.SimpleFilter() for _ in range(spec["inputs"])]
    if spec["kind"] == "exact":
        sync = message_filters.TimeSynchronizer(sources, spec["queue_size"])
    else:
        sync = message_filters.ApproximateTimeSynchronizer(sources, spec["queue_size"], spec["slop"])
    out = []
    sync.registerCallback(
        lambda *msgs: out.append([[m.header.stamp.secs, m.header.stamp.nsecs] for m in msgs])
    )
    for index, secs, nsecs in spec["events"]:
        sources[index].signalMessage(Msg(secs, nsecs))
    json.dump(out, sys.stdout)


main()

"""Random tf2 BufferCore operations, printed as JSON: run under Debian's ROS 1 and under ninjemys (both offer
``tf2_py.BufferCore``) and compare. Half the rotations are about z only, so chains mix planar and general
links. Stamps never repeat per frame: a repeated stamp is where we differ on
purpose (the newest data wins; tf2 keeps the first). With TF2_PATH=reference in the environment (ours
only) the buffer answers with tf2's walk alone (``BufferCore(fast=False)``)."""

import json
import math
import os
import random
import sys

import rospy
import tf2_py
from geometry_msgs.msg import TransformStamped


def run(seed):
    rnd = random.Random(seed)
    names = ["f%d" % i for i in range(12)]
    parents = {names[i]: names[rnd.randrange(i)] for i in range(1, 12)}
    buf = tf2_py.BufferCore(rospy.Duration(3))
    used = set()
    out = []
    for _ in range(400):
        if rnd.random() < 0.55:
            child = rnd.choice(names[1:])
            if rnd.random() < 0.03:  # a new parent (an earlier frame: never a loop)
                parents[child] = names[rnd.randrange(names.index(child))]
            stamp = (rnd.randrange(0, 12), rnd.choice([0, 250000000, 500000000]))
            if (child, stamp) in used:
                continue
            used.add((child, stamp))
            m = TransformStamped()
            m.header.frame_id, m.child_frame_id = parents[child], child
            m.header.stamp = rospy.Time(*stamp)
            t, r = m.transform.translation, m.transform.rotation
            t.x, t.y, t.z = (rnd.uniform(-2, 2) for _ in range(3))
            q = [rnd.gauss(0, 1) for _ in range(4)]
            if rnd.random() < 0.5:  # about z only (a planar link, our complex-number path)
                q[0] = q[1] = 0.0
            n = math.sqrt(sum(v * v for v in q))
            r.x, r.y, r.z, r.w = (v / n for v in q)
            (buf.set_transform_static if rnd.random() < 0.1 else buf.set_transform)(m, "peer")
            continue
        target, source = rnd.choice(names), rnd.choice(names)
        if rnd.random() < 0.4:
            when = rospy.Time(0)
        else:
            when = rospy.Time(rnd.randrange(0, 12), rnd.choice([0, 100000000, 600000000]))
        try:
            m = buf.lookup_transform_core(target, source, when)
            q = [
                m.transform.rotation.x,
                m.transform.rotation.y,
                m.transform.rotation.z,
                m.transform.rotation.w,
            ]
            if q[3] < 0:
                q = [-v for v in q]
            t = m.transform.translation
            out.append(["ok", target, source, [m.header.stamp.secs, m.header.stamp.nsecs, t.x, t.y, t.z] + q])
        except tf2_py.TransformException as e:
            out.append([type(e).__name__, target, source, str(e)])
        ok, why = buf.can_transform_core(target, source, when)
        out.append(["can", bool(ok), why])
    out.append(["yaml", buf.all_frames_as_yaml()])
    return out


if __name__ == "__main__":
    if os.environ.get("TF2_PATH") == "reference":
        import ninjemys.tf2.core

        ninjemys.tf2.core.FAST = False
    print(json.dumps([run(int(seed)) for seed in sys.argv[1:]]))

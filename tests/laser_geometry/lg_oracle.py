"""Debian's laser_geometry on serialized scans (run under /usr/bin/python3).

stdin: JSON list of {"scan": base64 LaserScan, "cutoff": float, "options": int}; stdout: JSON list of
base64 PointCloud2.
"""

import base64
import io
import json
import sys

import rospy.rostime
from laser_geometry import LaserProjection
from sensor_msgs.msg import LaserScan

rospy.rostime.set_rostime_initialized(True)

projector = LaserProjection()
out = []
for case in json.load(sys.stdin):
    scan = LaserScan().deserialize(base64.b64decode(case["scan"]))
    cloud = projector.projectLaser(scan, case["cutoff"], case["options"])
    buff = io.BytesIO()
    cloud.serialize(buff)
    out.append(base64.b64encode(buff.getvalue()).decode())
json.dump(out, sys.stdout)

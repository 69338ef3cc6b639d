"""Debian's cv_bridge on serialized images (run under /usr/bin/python3).

stdin: JSON {"images": [base64 sensor_msgs/Image], "targets": [encoding], "arrays": [[npy base64, encoding]]}
stdout: JSON {"convert": [[[shape, dtype, base64 bytes] | "ERR"]], "to_msg": [base64 Image | "ERR"]}
"""

import base64
import io
import json
import sys

import numpy as np

from cv_bridge import CvBridge, CvBridgeError
from sensor_msgs.msg import Image

bridge = CvBridge()
spec = json.load(sys.stdin)
converted = []
for data in spec["images"]:
    msg = Image().deserialize(base64.b64decode(data))
    row = []
    for target in spec["targets"]:
        try:
            im = np.ascontiguousarray(bridge.imgmsg_to_cv2(msg, target))
            row.append([list(im.shape), im.dtype.str, base64.b64encode(im.tobytes()).decode()])
        except CvBridgeError:
            row.append("ERR")
    converted.append(row)
to_msg = []
for npy, encoding in spec["arrays"]:
    arr = np.load(io.BytesIO(base64.b64decode(npy)))
    try:
        msg = bridge.cv2_to_imgmsg(arr, encoding)
        buff = io.BytesIO()
        msg.serialize(buff)
        to_msg.append(base64.b64encode(buff.getvalue()).decode())
    except (CvBridgeError, TypeError):
        to_msg.append("ERR")
json.dump({"convert": converted, "to_msg": to_msg}, sys.stdout)

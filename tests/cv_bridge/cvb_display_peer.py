"""cv_bridge.boost.cv_bridge_boost on fixed images, printed as JSON (run under either interpreter):
cvtColorForDisplay (depth scaling, label colors, guessed outputs, every error text), getCvType and
cvtColor2. tests/cv_bridge/test_cv_bridge_display.py compares ours with Debian's."""

import json

import numpy as np

from cv_bridge import CvBridge
from cv_bridge.boost.cv_bridge_boost import cvtColor2, cvtColorForDisplay, getCvType

depth = np.array([[0.5, 1.0], [2.0, 20.0]], np.float32)
depth16 = np.array([[0, 1000], [5000, 20000]], np.uint16)
mono = np.array([[0, 100], [200, 255]], np.uint8)
rgb = np.arange(12, dtype=np.uint8).reshape(2, 2, 3)
bgra = np.arange(16, dtype=np.uint8).reshape(2, 2, 4)
rgb16 = np.arange(12, dtype=np.uint16).reshape(2, 2, 3) * 1000
labels = np.arange(-150, 300, dtype=np.int32).reshape(3, -1)
flat = np.full((2, 2), 7, np.float32)
DISPLAY = [
    (depth, "32FC1", ""),
    (depth, "32FC1", "bgr8", True),
    (depth, "32FC1", "mono8", True),
    (depth, "32FC1", "bgr8", False, 0.0, 4.0),
    (depth, "32FC1", "bgr8", False, 5.0, 1.0),
    (depth, "32FC1", "mono16", True),
    (depth16, "16UC1", ""),
    (depth16, "16UC1", "bgr8", True),
    (depth16, "16UC1", "mono8"),
    (depth16, "mono16", ""),
    (depth16, "16SC1", ""),
    (depth16, "16UC1", "bgr8", False, 1000, 3000),
    (mono, "mono8", ""),
    (mono, "8UC1", ""),
    (mono, "mono8", "rgb8"),
    (mono, "8UC1", "", True),
    (rgb, "rgb8", ""),
    (rgb, "bgr8", ""),
    (rgb, "8UC3", ""),
    (rgb, "rgb8", "mono8"),
    (rgb, "rgb8", "32FC1"),
    (rgb, "rgb8", "rgba8"),
    (rgb, "rgb8", "bgr8", True),
    (bgra, "bgra8", ""),
    (rgb16, "rgb16", ""),
    (labels, "32SC1", ""),
    (labels, "32SC1", "mono8"),
    (flat, "32FC1", "mono8", True),
    (np.zeros((2, 2)), "64FC1", ""),
    (mono, "foo", ""),
]


def outcome(fn, *args):
    try:
        r = np.asarray(fn(*args))
        return [list(r.shape), str(r.dtype), r.reshape(-1).tolist()]
    except Exception as exc:  # the class and the text are what is compared
        return [[c.__name__ for c in type(exc).__mro__ if c.__module__ == "builtins"][0], str(exc)]


out = [outcome(cvtColorForDisplay, *a) for a in DISPLAY]
out += [outcome(getCvType, e) for e in ("bgr8", "mono16", "32FC3", "bayer_rggb8", "yuv422", "16SC4", "foo")]
for a in ((rgb, "rgb8", "bgr8"), (rgb, "rgb8", "32FC1"), (rgb, "foo", "bgr8"), (rgb, "8UC3", "bgr8")):
    out.append(outcome(cvtColor2, *a))
bridge = CvBridge()
for enc in ("bgr8", "mono16", "32FC1", "8SC4", "nope"):
    out.append(outcome(lambda e=enc: [bridge.encoding_to_cvtype2(e)]))
    out.append(outcome(lambda e=enc: list(bridge.encoding_to_dtype_with_channels(e))))
for dtype, channels in (("uint8", 3), ("float32", 1), ("int16", 2), ("float64", 4)):
    out.append(outcome(lambda d=dtype, c=channels: [bridge.dtype_with_channels_to_cvtype2(np.dtype(d), c)]))
for cvtype in (0, 16, 21, 13, 30):
    out.append(outcome(lambda t=cvtype: list(bridge.cvtype2_to_dtype_with_channels(t))))
print(json.dumps(out))

"""cv_bridge conversions: ninjemys vs Debian's python3-cv-bridge (with python3-opencv), one run.

    .venv/bin/python bench/cv_bridge.py [--repeat 30]

The same program runs under our venv (our cv_bridge, opencv-python-headless) and under
/usr/bin/python3 (Debian's cv_bridge and OpenCV) and times, for 640x480 and 1920x1080 rgb8 frames:
``imgmsg_to_cv2`` passthrough and to bgr8/mono8, ``cv2_to_imgmsg`` (bgr8), and the compressed pair
(``cv2_to_compressed_imgmsg`` jpg, ``compressed_imgmsg_to_cv2``). Then the compressed publisher's cost:
ninjemys.image_transport.encode per frame (compressed_image_transport's defaults: jpeg quality 80,
png level 9) and the CPU share that makes at 30 frames/s. A publisher nobody subscribes to encodes
nothing (tests/image_transport/test_compressed.py), so its idle cost is zero.
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import time

from ninjemys.testing import have_ros1

PROGRAM = r"""
import json, sys, time
import numpy as np
from cv_bridge import CvBridge
from sensor_msgs.msg import Image
repeat = int(sys.argv[1])
b = CvBridge()
out = {}
rng = np.random.default_rng(1)
for w, h in ((640, 480), (1920, 1080)):
    arr = rng.integers(0, 256, (h, w, 3), dtype=np.uint8)
    msg = b.cv2_to_imgmsg(arr, "rgb8")
    msg = Image(height=h, width=w, encoding="rgb8", step=w * 3, data=arr.tobytes())
    jpg = b.cv2_to_compressed_imgmsg(arr)
    cases = {
        "imgmsg_to_cv2 passthrough": lambda: b.imgmsg_to_cv2(msg),
        "imgmsg_to_cv2 rgb8->bgr8": lambda: b.imgmsg_to_cv2(msg, "bgr8"),
        "imgmsg_to_cv2 rgb8->mono8": lambda: b.imgmsg_to_cv2(msg, "mono8"),
        "cv2_to_imgmsg bgr8": lambda: b.cv2_to_imgmsg(arr, "bgr8"),
        "cv2_to_compressed_imgmsg jpg": lambda: b.cv2_to_compressed_imgmsg(arr),
        "compressed_imgmsg_to_cv2 jpg": lambda: b.compressed_imgmsg_to_cv2(jpg),
    }
    for name, fn in cases.items():
        fn()
        best = float("inf")
        for _ in range(repeat):
            t = time.perf_counter(); fn(); best = min(best, time.perf_counter() - t)
        out[f"{w}x{h} {name}"] = best
print(json.dumps(out))
"""


def run(python: str, repeat: int) -> dict[str, float]:
    res = subprocess.run([python, "-c", PROGRAM, str(repeat)], capture_output=True, text=True, timeout=600)
    if res.returncode != 0:
        raise SystemExit(f"{python}: {res.stderr.strip()[-2000:]}")
    return json.loads(res.stdout)


def publisher_cost(repeat: int) -> None:
    import numpy as np

    from ninjemys.cv_bridge import CvBridge
    from ninjemys.image_transport import CompressionParams, encode

    bridge = CvBridge()
    rng = np.random.default_rng(2)
    print("\ncompressed publisher (ninjemys.image_transport.encode per frame; CPU at 30 fps)")
    for w, h in ((320, 240), (640, 480)):
        y, x = np.mgrid[0:h, 0:w]  # a smooth scene with noise, closer to a camera than pure noise
        arr = (np.dstack([x % 256, y % 256, (x + y) % 256]) + rng.integers(0, 8, (h, w, 3))).astype(np.uint8)
        msg = bridge.cv2_to_imgmsg(arr, "rgb8")
        for params in (CompressionParams("jpeg"), CompressionParams("png")):
            encode(msg, params)
            best = float("inf")
            for _ in range(repeat):
                t = time.process_time()
                encode(msg, params)
                best = min(best, time.process_time() - t)
            print(
                f"  {w}x{h} {params.format:5s} {best * 1e3:8.2f} ms/frame  {best * 30 * 100:6.1f} % of a core at 30 fps"
            )


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=30)
    args = ap.parse_args(argv)
    ours = run(sys.executable, args.repeat)
    theirs = run("/usr/bin/python3", args.repeat) if have_ros1() else {}
    print(f"{'case':48s} {'ninjemys ms':>12s} {'Debian ms':>10s} {'ratio':>7s}")
    for key, t in ours.items():
        d = theirs.get(key)
        ratio = f"{t / d:7.2f}" if d else "      -"
        print(f"{key:48s} {t * 1e3:12.3f} {(d or float('nan')) * 1e3:10.3f} {ratio}")
    print("(ratio = ninjemys / Debian time; < 1 is faster; best of --repeat)")
    publisher_cost(args.repeat)
    return 0


if __name__ == "__main__":
    sys.exit(main())

"""rqt in headless chromium: rqt_image_view on a 640x480 camera at 30 Hz, rqt_plot of 3 series at 100 Hz.

    .venv/bin/python bench/web_rqt.py [--seconds 10]

A helper process (ninjemys nodes) publishes; rqt (node + gateway + web app) runs in this process;
the page is Debian's chromium via Playwright. ROS 1's rqt_image_view and rqt_plot are Qt desktop
tools (not installed here), so the reference run side by side is Debian's rospy subscribing to the
same topics under /usr/bin/python3 (what any ROS 1 viewer must do before drawing): its message rate
and CPU against ours (gateway CPU in this process, page CPU from Chrome's Performance metrics).
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import textwrap
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "src"))

from ninjemys.testing import ROS1_PYTHON, ros1_env, run_master  # noqa: E402
from ninjemys.web.rqt import Rqt, tool_url  # noqa: E402

PUBLISHER = textwrap.dedent(
    """
    import math, sys, time
    from ninjemys.idl.loader import get_message_class
    from ninjemys.node import Node
    mode = sys.argv[1]
    node = Node("bench_source")
    if mode == "camera":
        Image = get_message_class("sensor_msgs/Image")
        pub = node.publisher("/camera/image_raw", Image, queue_size=2)
        frames = [bytes([(k * 8) % 256]) * (640 * 480 * 3) for k in range(8)]
        period, k = 1 / 30, 0
        while True:
            msg = Image(height=480, width=640, encoding="rgb8", step=640 * 3, data=frames[k % 8])
            msg.header.frame_id = "camera"
            pub.publish(msg)
            k += 1
            time.sleep(max(0.0, period - (time.monotonic() % period)))
    else:
        Float64 = get_message_class("std_msgs/Float64")
        pubs = [node.publisher(f"/series{i}", Float64, queue_size=10) for i in range(3)]
        k = 0
        while True:
            for i, p in enumerate(pubs):
                p.publish(Float64(data=math.sin(k * 0.05 + i)))
            k += 1
            time.sleep(0.01)
    """
)

REFERENCE = textwrap.dedent(
    """
    import resource, sys, time
    import rospy
    from sensor_msgs.msg import Image
    from std_msgs.msg import Float64
    seconds, mode = float(sys.argv[1]), sys.argv[2]
    rospy.init_node("bench_reference", anonymous=True)
    count = [0]
    def cb(_m):
        count[0] += 1
    if mode == "camera":
        rospy.Subscriber("/camera/image_raw", Image, cb, queue_size=2)
    else:
        for i in range(3):
            rospy.Subscriber(f"/series{i}", Float64, cb, queue_size=10)
    time.sleep(3.0)  # connect and settle, as the page does
    c0, r0 = count[0], resource.getrusage(resource.RUSAGE_SELF)
    t0 = time.monotonic()
    time.sleep(seconds)
    r1, wall = resource.getrusage(resource.RUSAGE_SELF), time.monotonic() - t0
    cpu = (r1.ru_utime + r1.ru_stime) - (r0.ru_utime + r0.ru_stime)
    print(f"{(count[0] - c0) / wall:.2f} {cpu / wall:.4f}", flush=True)
    """
)


def _cpu() -> float:
    t = os.times()
    return t.user + t.system


def _page_cpu(cdp) -> float:  # type: ignore[no-untyped-def]
    metrics = {m["name"]: m["value"] for m in cdp.send("Performance.getMetrics")["metrics"]}
    return metrics["TaskDuration"]


def run(mode: str, seconds: float, uri: str, browser) -> dict[str, float]:  # type: ignore[no-untyped-def]
    env = dict(os.environ, ROS_MASTER_URI=uri)
    source = subprocess.Popen([sys.executable, "-c", PUBLISHER, mode], env=env)
    reference = subprocess.Popen(
        [ROS1_PYTHON, "-c", REFERENCE, str(seconds), mode],
        env=ros1_env(uri),
        stdout=subprocess.PIPE,
        text=True,
    )
    rqt = Rqt(uri, update_period=0.5)
    try:
        base = rqt.start()
        if mode == "camera":
            url = tool_url(base, "image_view", [("topic", "/camera/image_raw")])
            counter = "[window.rqt.tools.image_view.frames, window.rqt.tools.image_view.received]"
        else:
            url = tool_url(base, "plot", [("topic", f"/series{i}/data") for i in range(3)])
            counter = "[Object.values(window.rqt.tools.plot.data()).reduce((a, s) => a + s.length, 0), 0]"
        page = browser.new_page(viewport={"width": 1280, "height": 900})
        cdp = page.context.new_cdp_session(page)
        cdp.send("Performance.enable")
        page.goto(url)
        page.wait_for_function("window.rqt && window.rqt.ready", timeout=30000)
        time.sleep(3.0)  # the topic is advertised and the stream settles
        n0, p0, c0, t0 = page.evaluate(counter), _page_cpu(cdp), _cpu(), time.monotonic()
        time.sleep(seconds)
        n1, p1, c1, wall = page.evaluate(counter), _page_cpu(cdp), _cpu(), time.monotonic() - t0
        page.close()
        ref_rate, ref_cpu = map(float, reference.communicate(timeout=seconds + 30)[0].split())
        return {
            "rate": (n1[0] - n0[0]) / wall,
            "received": (n1[1] - n0[1]) / wall,
            "page_cpu": (p1 - p0) / wall,
            "gateway_cpu": (c1 - c0) / wall,
            "ref_rate": ref_rate,
            "ref_cpu": ref_cpu,
        }
    finally:
        rqt.stop()
        for proc in (source, reference):
            if proc.poll() is None:
                proc.kill()
            proc.wait()


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--seconds", type=float, default=10.0)
    options = parser.parse_args()
    from playwright.sync_api import sync_playwright

    print(f"load average: {os.getloadavg()[0]:.2f} {os.getloadavg()[1]:.2f} (2 cores)")
    with run_master() as uri, sync_playwright() as pw:
        browser = pw.chromium.launch(
            executable_path="/usr/bin/chromium", args=["--no-sandbox", "--disable-gpu"]
        )
        try:
            cam = run("camera", options.seconds, uri, browser)
            print(
                f"rqt_image_view 640x480 rgb8 @ 30 Hz: {cam['rate']:.1f} frames shown/s "
                f"of {cam['received']:.1f} received by the page "
                f"(rospy subscriber: {cam['ref_rate']:.1f} msgs/s; ratio {cam['rate'] / cam['ref_rate']:.2f}); "
                f"page CPU {cam['page_cpu'] * 100:.0f}%, gateway CPU {cam['gateway_cpu'] * 100:.0f}%, "
                f"rospy subscriber CPU {cam['ref_cpu'] * 100:.0f}%"
            )
            plot = run("plot", options.seconds, uri, browser)
            print(
                f"rqt_plot 3 series @ 100 Hz: {plot['rate']:.0f} samples/s plotted "
                f"(rospy subscriber: {plot['ref_rate']:.0f} msgs/s); page CPU {plot['page_cpu'] * 100:.0f}%, "
                f"gateway CPU {plot['gateway_cpu'] * 100:.0f}%, rospy subscriber CPU {plot['ref_cpu'] * 100:.0f}% "
                f"(page+gateway / rospy: {(plot['page_cpu'] + plot['gateway_cpu']) / max(plot['ref_cpu'], 1e-6):.1f}x)"
            )
        finally:
            browser.close()


if __name__ == "__main__":
    main()

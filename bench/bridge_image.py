"""A 640x480 rgb8 stream at 30 Hz through the gateway to one WebSocket client: drops and gateway CPU.

Run: ``.venv/bin/python bench/bridge_image.py [seconds]``. Target: no drops on localhost.

The images (921,600 bytes each, 27.6 MB/s) come from a publisher in this process; one client takes
them from the gateway as Foxglove binary (the TCPROS bytes as received) and, in a second run, as
rosbridge JSON (base64 inside JSON, what roslibjs receives). The reference is ROS 1's own relay
(``topic_tools relay``, C++, from Debian) forwarding the same stream to one TCPROS subscriber: the
cheapest way ROS 1 has to receive and re-send it.
"""

from __future__ import annotations

import asyncio
import json
import os
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

from websockets.asyncio.client import connect

from bridge_common import cpu_seconds, gateway
from ninjemys.idl.loader import get_message_class
from ninjemys.node import Node
from ninjemys.testing import ros1_env
from node_common import header, master, ratio

RATE = 30.0
RELAY = Path("/usr/lib/topic_tools/relay")
Image = get_message_class("sensor_msgs/Image")


class Camera:
    """Publishes 640x480 rgb8 images at 30 Hz on a thread while ``running``."""

    def __init__(self, uri: str) -> None:
        self.node = Node("bench_camera", anonymous=True, master_uri=uri)
        self.pub = self.node.publisher("/image", Image, queue_size=2)
        self.sent = 0
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None

    def start(self, seconds: float) -> None:
        img = Image(height=480, width=640, encoding="rgb8", step=1920, data=bytes(range(256)) * 3600)

        def run() -> None:
            nxt, end = time.perf_counter(), time.monotonic() + seconds
            while time.monotonic() < end and not self._stop.is_set():
                self.pub.publish(img)
                self.sent += 1
                nxt += 1 / RATE
                time.sleep(max(0.0, nxt - time.perf_counter()))

        self._thread = threading.Thread(target=run, daemon=True)
        self._thread.start()

    def join(self) -> None:
        assert self._thread is not None
        self._thread.join()

    def close(self) -> None:
        self._stop.set()
        self.node.shutdown("bench over")


async def _receive(url: str, protocol: str, seconds: float, ready: threading.Event) -> int:
    subprotocols = ["foxglove.websocket.v1"] if protocol == "foxglove" else None
    count = 0
    async with connect(url, subprotocols=subprotocols, max_size=None) as ws:
        if protocol == "foxglove":
            while True:
                msg = json.loads(await ws.recv())
                channel = next((c for c in msg.get("channels", []) if c["topic"] == "/image"), None)
                if channel is not None:
                    break
            await ws.send(
                json.dumps({"op": "subscribe", "subscriptions": [{"id": 1, "channelId": channel["id"]}]})
            )
        else:
            await ws.send(json.dumps({"op": "subscribe", "topic": "/image", "type": "sensor_msgs/Image"}))
        ready.set()
        end = time.monotonic() + seconds
        while time.monotonic() < end:
            try:
                data = await asyncio.wait_for(ws.recv(), end - time.monotonic())
            except TimeoutError:
                break
            if isinstance(data, bytes) and data[0] == 1:
                count += 1
            elif isinstance(data, str) and data.startswith('{"op": "publish"'):
                count += 1
    return count


def through_gateway(uri: str, protocol: str, seconds: float) -> dict:
    camera = Camera(uri)
    try:
        with gateway(uri) as gw:
            ready = threading.Event()
            result: list[int] = []
            client = threading.Thread(
                target=lambda: result.append(asyncio.run(_receive(gw.url, protocol, seconds + 5.0, ready))),
                daemon=True,
            )
            client.start()
            ready.wait(30)
            deadline = time.monotonic() + 30
            while camera.pub.get_num_connections() < 1 and time.monotonic() < deadline:
                time.sleep(0.05)
            time.sleep(0.3)
            cpu0, t0 = gw.cpu(), time.monotonic()
            camera.start(seconds)
            camera.join()
            cpu = (gw.cpu() - cpu0) / (time.monotonic() - t0)
            client.join(30)
    finally:
        camera.close()
    received = result[0] if result else 0
    return {"sent": camera.sent, "received": received, "cpu": cpu * 100}


def through_relay(uri: str, seconds: float) -> dict | None:
    if not RELAY.exists():
        return None
    env = ros1_env(uri)
    env["ROS_HOME"] = tempfile.mkdtemp(prefix="bench_relay_home_")
    relay = subprocess.Popen(
        [str(RELAY), "/image", "/image_relay"], env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL
    )
    camera = Camera(uri)
    viewer = Node("bench_viewer", anonymous=True, master_uri=uri)
    got = [0]
    try:
        viewer.subscriber(
            "/image_relay", None, lambda m: got.__setitem__(0, got[0] + 1), raw=True, queue_size=100
        )
        deadline = time.monotonic() + 30
        while camera.pub.get_num_connections() < 1 and time.monotonic() < deadline:
            time.sleep(0.05)
        time.sleep(1.0)
        cpu0, t0 = cpu_seconds(relay.pid), time.monotonic()
        camera.start(seconds)
        camera.join()
        cpu = (cpu_seconds(relay.pid) - cpu0) / (time.monotonic() - t0)
        time.sleep(1.0)
        return {"sent": camera.sent, "received": got[0], "cpu": cpu * 100}
    finally:
        camera.close()
        viewer.shutdown("bench over")
        relay.terminate()
        relay.wait(10)


def main() -> None:
    seconds = float(sys.argv[1]) if len(sys.argv) > 1 else 5.0
    header(f"640x480 rgb8 at {RATE:.0f} Hz (27.6 MB/s) to one client for {seconds:.0f} s")
    os.environ.setdefault("ROS_HOSTNAME", "localhost")
    with master() as uri:
        results = {p: through_gateway(uri, p, seconds) for p in ("foxglove", "rosbridge")}
        ref = through_relay(uri, seconds)
    for proto, r in results.items():
        drops = r["sent"] - r["received"]
        print(
            f"gateway {proto:9s} sent {r['sent']:4d}  received {r['received']:4d}  drops {drops:3d}   gateway CPU {r['cpu']:5.1f}% of a core"
        )
    if ref is not None:
        print(
            f"topic_tools relay (C++) sent {ref['sent']:4d}  received {ref['received']:4d}   relay CPU {ref['cpu']:5.1f}% of a core"
        )
        for proto, r in results.items():
            print(f"ratio gateway {proto} / relay CPU {ratio(r['cpu'], ref['cpu'])}")


if __name__ == "__main__":
    main()

"""1,000 small messages/s fanned out by the gateway to 10 WebSocket clients: gateway CPU, latency p50/p99.

Run: ``.venv/bin/python bench/bridge_fanout.py [seconds]``. A publisher (rospy under Debian's Python
when ROS 1 is installed, else ours) sends std_msgs/Header at 1 kHz stamped with the wall time just
before publish; 10 clients (rosbridge JSON, then Foxglove binary) take it from the gateway, and each
delivery's latency is its receive wall time minus the stamp. The reference is the same publisher
fanning out to 10 native rospy subscribers over TCPROS (no gateway), in the same run.
"""

from __future__ import annotations

import asyncio
import json
import struct
import sys
import time

from websockets.asyncio.client import connect

from bridge_common import gateway, pct
from node_common import IMPLS, OURS, REAL, Role, header, master, ratio, roles
from node_fanout import run as native_fanout

CLIENTS = 10
_STAMP = struct.Struct("<II")


async def _client(url: str, protocol: str, seconds: float, out: list[float]) -> None:
    subprotocols = ["foxglove.websocket.v1"] if protocol == "foxglove" else None
    async with connect(url, subprotocols=subprotocols, max_size=None) as ws:
        if protocol == "foxglove":
            while True:
                msg = json.loads(await ws.recv())
                if msg["op"] == "advertise":
                    channel = next((c for c in msg["channels"] if c["topic"] == "/fan"), None)
                    if channel is not None:
                        break
            await ws.send(
                json.dumps({"op": "subscribe", "subscriptions": [{"id": 1, "channelId": channel["id"]}]})
            )
        else:
            await ws.send(json.dumps({"op": "subscribe", "topic": "/fan", "type": "std_msgs/Header"}))
        end = time.monotonic() + seconds
        lat: list[float] = []
        while time.monotonic() < end:
            try:
                data = await asyncio.wait_for(ws.recv(), end - time.monotonic())
            except TimeoutError:
                break
            now = time.time()
            if isinstance(data, bytes):
                if data[0] != 1:
                    continue
                secs, nsecs = _STAMP.unpack_from(data, 13 + 4)
            else:
                msg = json.loads(data)
                if msg.get("op") != "publish":
                    continue
                stamp = msg["msg"]["stamp"]
                secs, nsecs = stamp["secs"], stamp["nsecs"]
            lat.append(now - (secs + nsecs * 1e-9))
        out.extend(lat[200:])  # skip the start-up


def through_gateway(uri: str, impl: str, protocol: str, seconds: float) -> dict:
    with gateway(uri) as gw:
        pub = Role(impl, uri, "fan_pub", "1", str(seconds))
        with roles(pub):
            lat: list[float] = []

            async def clients() -> float:
                tasks = [
                    asyncio.create_task(_client(gw.url, protocol, seconds + 2.0, lat)) for _ in range(CLIENTS)
                ]
                await asyncio.sleep(1.5)  # the publisher waits 0.5 s after the gateway connects
                cpu0, t0 = gw.cpu(), time.monotonic()
                await asyncio.sleep(max(0.5, seconds - 1.0))
                cpu = (gw.cpu() - cpu0) / (time.monotonic() - t0)
                await asyncio.gather(*tasks)
                return cpu

            cpu = asyncio.run(clients())
    return {"p50": pct(lat, 0.5) * 1e3, "p99": pct(lat, 0.99) * 1e3, "n": len(lat), "cpu": cpu * 100}


def main() -> None:
    seconds = float(sys.argv[1]) if len(sys.argv) > 1 else 5.0
    impl = REAL if REAL in IMPLS else OURS
    header(
        f"fan-out 1 kHz std_msgs/Header -> {CLIENTS} WebSocket clients for {seconds:.0f} s (publisher: {impl})"
    )
    with master() as uri:
        results = {p: through_gateway(uri, impl, p, seconds) for p in ("rosbridge", "foxglove")}
        p50, p99, n = native_fanout(uri, impl, str(seconds))
    for proto, r in results.items():
        print(
            f"gateway {proto:9s} p50 {r['p50']:6.2f} ms   p99 {r['p99']:7.2f} ms   gateway CPU {r['cpu']:5.1f}% of a core   ({r['n']} deliveries)"
        )
    print(
        f"native {impl} TCPROS  p50 {p50 / 1e3:6.2f} ms   p99 {p99 / 1e3:7.2f} ms   ({n} deliveries, no gateway)"
    )
    for proto, r in results.items():
        print(f"ratio {proto} / native: p50 {ratio(r['p50'], p50 / 1e3)}   p99 {ratio(r['p99'], p99 / 1e3)}")


if __name__ == "__main__":
    main()

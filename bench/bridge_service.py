"""Service call round trip through the gateway with roslibpy, beside the direct TCPROS call.

Run: ``.venv/bin/python bench/bridge_service.py [calls]``. Target: p50 <= 5 ms through the gateway
(roslibjs users report 30 ms or more through rosbridge: roslibjs#162, Nagle's delay on the socket).

One std_srvs/Trigger server (rospy under Debian's Python when ROS 1 is installed, else ours) is
called (a) by roslibpy through the gateway (rosbridge v2 JSON over WebSocket, then a persistent
TCPROS call) and (b) directly by a persistent rospy ServiceProxy: (b) is the floor the gateway adds to.
"""

from __future__ import annotations

import sys
import time

from bridge_common import gateway, pct
from node_common import IMPLS, OURS, REAL, Role, header, master, ratio, roles

ANCHOR_MS = 30.0  # roslibjs#162


def through_gateway(uri: str, calls: int) -> dict:
    import roslibpy

    with gateway(uri) as gw:
        ros = roslibpy.Ros("127.0.0.1", gw.port)
        ros.run(timeout=30)
        try:
            service = roslibpy.Service(ros, "/bench_trigger", "std_srvs/Trigger")
            for _ in range(20):  # warm-up: type probe, persistent connection
                service.call(roslibpy.ServiceRequest({}), timeout=10)
            rtts = []
            cpu0 = gw.cpu()
            for _ in range(calls):
                t0 = time.perf_counter()
                reply = service.call(roslibpy.ServiceRequest({}), timeout=10)
                rtts.append(time.perf_counter() - t0)
                assert reply["success"] is True
            cpu = gw.cpu() - cpu0
        finally:
            ros.close()
    return {"p50": pct(rtts, 0.5) * 1e3, "p99": pct(rtts, 0.99) * 1e3, "cpu_ms_per_call": cpu / calls * 1e3}


def main() -> None:
    calls = int(sys.argv[1]) if len(sys.argv) > 1 else 500
    header(f"service round trip: roslibpy -> gateway -> TCPROS, {calls} calls")
    server_impl = REAL if REAL in IMPLS else OURS
    with master() as uri:
        server = Role(server_impl, uri, "trigger_server")
        with roles(server):
            server.ready()
            ours = through_gateway(uri, calls)
            direct = Role(server_impl, uri, "trigger_client", str(calls))
            with roles(direct):
                floor = direct.result()
    floor_p50 = floor.get("p50_us", float("nan")) / 1e3
    floor_p99 = floor.get("p99_us", float("nan")) / 1e3
    print(f"(server: {server_impl})")
    print(
        f"gateway (roslibpy)    p50 {ours['p50']:7.2f} ms   p99 {ours['p99']:7.2f} ms   gateway CPU {ours['cpu_ms_per_call']:.2f} ms/call"
    )
    print(f"direct {server_impl:6s} proxy   p50 {floor_p50:7.2f} ms   p99 {floor_p99:7.2f} ms")
    print(f"roslibjs#162 anchor   p50 >= {ANCHOR_MS:.0f} ms")
    print(
        f"ratio gateway/direct p50 {ratio(ours['p50'], floor_p50)}   gateway/anchor {ratio(ours['p50'], ANCHOR_MS)}"
    )
    print(f"target p50 <= 5 ms: {'met' if ours['p50'] <= 5.0 else 'NOT met'}")


if __name__ == "__main__":
    main()

"""Master at scale, ninjemys vs Debian's ROS 1 in one run.

    .venv/bin/python bench/master_scale.py [--nodes 1000] [--threads 4]

Registers NODES nodes x 10 publishers + 10 subscribers (spread over NODES topics; the node APIs
point at closed ports, so every publisherUpdate the masters send fails fast, as for nodes that died),
then times getSystemState (median of 5) and registerSubscriber on a topic with 100 publishers
(median of 20 new subscribers). Every call's status code is checked; failures are counted. The
getSystemState figure is the wire round trip (request sent -> whole response received), so the
client's XML parsing is not counted for either master.
"""

from __future__ import annotations

import argparse
import socket
import threading
import time

from master_common import OURS, REAL, median, ratio, require_ros1, start_core, wait_ready
from ninjemys.errors import MasterError
from ninjemys.master.client import MasterClient
from ninjemys.net.addresses import split_uri
from ninjemys.wire import xmlrpc as wire

PER_NODE = 10


def _node_api(i: int) -> str:
    return f"http://127.0.0.1:{1 + i % 1000}/"  # ports below 1024 that nothing listens on


def register_all(uri: str, nodes: int, threads: int) -> tuple[float, int]:
    failures = [0]
    lock = threading.Lock()

    def work(first: int) -> None:
        bad = 0
        for i in range(first, nodes, threads):
            client = MasterClient(uri, f"/node_{i}", timeout=60)
            api = _node_api(i)
            for k in range(PER_NODE):
                try:
                    client.register_publisher(f"/topic_{(i * 7 + k) % nodes}", "std_msgs/String", api)
                    client.register_subscriber(f"/topic_{(i * 13 + k * 3) % nodes}", "std_msgs/String", api)
                except MasterError:
                    bad += 1
            client.close()
        with lock:
            failures[0] += bad

    start = time.perf_counter()
    workers = [threading.Thread(target=work, args=(t,)) for t in range(threads)]
    for w in workers:
        w.start()
    for w in workers:
        w.join()
    return time.perf_counter() - start, failures[0]


def _raw_round_trip(uri: str, body: bytes) -> tuple[float, bytes]:
    """Seconds from sending a call to having the whole response (the master's time, not our parsing)."""
    host, port = split_uri(uri)
    request = wire.http_request(host, port, body, keep_alive=False)
    with socket.create_connection((host, port), timeout=60) as sock:
        parser = wire.HttpResponseParser()
        t0 = time.perf_counter()
        sock.sendall(request)
        while True:
            data = sock.recv(1 << 20)
            if not data:
                raise RuntimeError("master closed the connection")
            messages = parser.feed(data)
            if messages:
                return time.perf_counter() - t0, messages[0].body


def time_system_state(uri: str, runs: int = 5) -> tuple[float, int]:
    body = wire.dump_call("getSystemState", ("/bench",))
    times = []
    for _ in range(runs):
        elapsed, reply = _raw_round_trip(uri, body)
        times.append(elapsed)
    code, _, state = wire.parse_response(reply)
    assert code == 1
    return median(times), sum(len(nodes) for part in state for _, nodes in part)


def time_hot_subscribe(uri: str, runs: int = 20) -> tuple[float, int]:
    for p in range(100):
        MasterClient(uri, f"/hot_pub_{p}").register_publisher("/hot", "std_msgs/String", _node_api(p))
    times = []
    got = 0
    for s in range(runs):
        client = MasterClient(uri, f"/hot_sub_{s}", timeout=60)
        client.get_pid()  # connect outside the timed call
        t0 = time.perf_counter()
        pubs = client.register_subscriber("/hot", "std_msgs/String", _node_api(500 + s))
        times.append(time.perf_counter() - t0)
        got = len(pubs)
        client.close()
    return median(times), got


def measure(impl: str, nodes: int, threads: int) -> dict[str, float]:
    core = start_core(impl)
    try:
        wait_ready(core)
        reg_time, failures = register_all(core.uri, nodes, threads)
        time.sleep(2.0)  # let each master finish the notifications the registrations caused
        state_time, entries = time_system_state(core.uri)
        hot_time, hot_pubs = time_hot_subscribe(core.uri)
        assert hot_pubs == 100, f"{impl}: registerSubscriber returned {hot_pubs} publishers"
        return {
            "register": reg_time,
            "calls_per_s": nodes * PER_NODE * 2 / reg_time,
            "failures": failures,
            "state": state_time,
            "entries": entries,
            "hot": hot_time,
        }
    finally:
        core.stop()
        core.kill()


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--nodes", type=int, default=1000)
    parser.add_argument("--threads", type=int, default=4, help="client threads registering in parallel")
    args = parser.parse_args()
    require_ros1()
    results = {impl: measure(impl, args.nodes, args.threads) for impl in (REAL, OURS)}
    r, o = results[REAL], results[OURS]
    calls = args.nodes * PER_NODE * 2
    print(
        f"master scale: {args.nodes} nodes x {PER_NODE} pub + {PER_NODE} sub ({calls} calls, {args.threads} threads)"
    )
    print(f"{'figure':<42}{REAL:>12}{OURS:>12}   ratio")
    print(
        f"{'register all (s)':<42}{r['register']:>12.2f}{o['register']:>12.2f}   {ratio(o['register'], r['register'])}"
    )
    print(f"{'  calls/s':<42}{r['calls_per_s']:>12.0f}{o['calls_per_s']:>12.0f}")
    print(f"{'  failed calls':<42}{r['failures']:>12}{o['failures']:>12}")
    print(
        f"{'getSystemState (ms, %d entries)' % o['entries']:<42}{r['state'] * 1e3:>12.1f}{o['state'] * 1e3:>12.1f}"
        f"   {ratio(o['state'], r['state'])}"
    )
    print(
        f"{'registerSubscriber, 100 publishers (ms)':<42}{r['hot'] * 1e3:>12.2f}{o['hot'] * 1e3:>12.2f}"
        f"   {ratio(o['hot'], r['hot'])}"
    )


if __name__ == "__main__":
    main()

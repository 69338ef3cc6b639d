"""turtlesim_node CPU use: idle, and 10 turtles driven at 60 Hz (plus a browser view streaming).

    .venv/bin/python bench/sim_turtlesim.py [--seconds 5]

Debian ships no turtlesim (the C++ node is not packaged there), so there is no ROS 1 process to run
side by side; the reference figures are ROS turtlesim's fixed 62.5 Hz update of the same topics.
CPU is read from /proc/<pid>/stat (user + system time) over the measuring window.
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import threading
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "src"))

from ninjemys.testing import free_port, ninjemys_bin, run_master  # noqa: E402

CLK_TCK = os.sysconf("SC_CLK_TCK")


def cpu_seconds(pid: int) -> float:
    fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / CLK_TCK


def measure(pid: int, seconds: float) -> float:
    """CPU % of one core used by ``pid`` over ``seconds``."""
    c0, t0 = cpu_seconds(pid), time.monotonic()
    time.sleep(seconds)
    return 100.0 * (cpu_seconds(pid) - c0) / (time.monotonic() - t0)


def start_turtlesim(uri: str, web_port: int | None) -> subprocess.Popen:
    env = dict(os.environ, ROS_MASTER_URI=uri, ROS_HOSTNAME="localhost")
    args = ["--port", str(web_port)] if web_port else ["--headless"]
    proc = subprocess.Popen(
        [ninjemys_bin("turtlesim_node"), *args],
        env=env,
        stdout=subprocess.PIPE,
        stderr=subprocess.DEVNULL,
        text=True,
    )
    assert proc.stdout is not None
    for line in proc.stdout:
        if ("turtlesim view:" if web_port else "Spawning turtle [turtle1]") in line:
            break
    threading.Thread(target=proc.stdout.read, daemon=True).start()
    return proc


def drive(uri: str, turtles: int, hz: float, stop: threading.Event) -> None:
    from geometry_msgs.msg import Twist
    from ninjemys.node import Node
    from turtlesim.srv import Spawn

    node = Node("bench_driver", anonymous=True, master_uri=uri)
    try:
        node.wait_for_service("/spawn", timeout=10)
        spawn = node.service_proxy("/spawn", Spawn)
        for i in range(2, turtles + 1):
            spawn(Spawn._request_class(x=1.0 + 0.9 * i, y=2.0, theta=1.0, name=""))
        pubs = [node.publisher(f"/turtle{i}/cmd_vel", Twist, queue_size=1) for i in range(1, turtles + 1)]
        deadline = time.monotonic() + 10
        while any(p.get_num_connections() == 0 for p in pubs) and time.monotonic() < deadline:
            time.sleep(0.05)
        twist = Twist()
        twist.linear.x, twist.angular.z = 0.5, 0.4
        period, next_t = 1.0 / hz, time.monotonic()
        while not stop.is_set():
            for p in pubs:
                p.publish(twist)
            next_t += period
            stop.wait(max(0.0, next_t - time.monotonic()))
    finally:
        node.shutdown("bench over")


def stream(url: str, stop: threading.Event, counter: list[int]) -> None:
    """A browser view's data path: the gateway's view:turtlesim channel, counting messages."""
    import json

    from websockets.sync.client import connect

    with connect(url, subprotocols=["foxglove.websocket.v1"]) as ws:
        while not stop.is_set():
            try:
                raw = ws.recv(timeout=0.5)
            except TimeoutError:
                continue
            if isinstance(raw, bytes):
                counter[0] += 1
                continue
            msg = json.loads(raw)
            if msg["op"] == "advertise":
                for ch in msg["channels"]:
                    if ch["topic"] == "view:turtlesim":
                        ws.send(
                            json.dumps(
                                {"op": "subscribe", "subscriptions": [{"id": 1, "channelId": ch["id"]}]}
                            )
                        )


def scenario(uri: str, seconds: float, turtles: int, web: bool) -> tuple[float, int]:
    port = free_port() if web else None
    proc = start_turtlesim(uri, port)
    stop = threading.Event()
    events = [0]
    threads = []
    try:
        if turtles:
            threads.append(threading.Thread(target=drive, args=(uri, turtles, 60.0, stop), daemon=True))
        if web:
            url = f"ws://localhost:{port}/ws"
            threads.append(threading.Thread(target=stream, args=(url, stop, events), daemon=True))
        for t in threads:
            t.start()
        time.sleep(3.0)  # spawning, connections, warm-up
        events[0] = 0
        cpu = measure(proc.pid, seconds)
        return cpu, int(events[0] / seconds)
    finally:
        stop.set()
        for t in threads:
            t.join(5)
        proc.terminate()
        try:
            proc.wait(5)
        except subprocess.TimeoutExpired:
            proc.kill()
            proc.wait()


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--seconds", type=float, default=5.0)
    options = parser.parse_args()
    print(
        f"turtlesim_node CPU (% of one core, {options.seconds:.0f} s windows; machine shared, figures noisy)"
    )
    print(f"{'scenario':52} {'CPU %':>7} {'view events/s':>14}")
    with run_master() as uri:
        for label, turtles, web in (
            ("idle, 1 turtle, headless", 0, False),
            ("idle, 1 turtle, browser view connected", 0, True),
            ("10 turtles, cmd_vel at 60 Hz each, headless", 10, False),
            ("10 turtles, cmd_vel at 60 Hz each, browser view", 10, True),
        ):
            cpu, rate = scenario(uri, options.seconds, turtles, web)
            print(f"{label:52} {cpu:7.1f} {rate if web else '-':>14}")
    print(
        "ROS 1 reference: not measurable here (no turtlesim package in Debian); ROS turtlesim does the same"
    )
    print("62.5 Hz pose + color_sensor publishing per turtle in C++.")


if __name__ == "__main__":
    main()

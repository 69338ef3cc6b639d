"""Large messages between processes on one host: ninjemys over SHMROS (shared memory, the default),
ninjemys over TCPROS (``NINJEMYS_SHM=0``), rospy and roscpp, side by side in one run.

Run: ``.venv/bin/python bench/node_shm.py [seconds]``. Rows:

* 1920x1080 rgb8 Image: one-way p50 (images 50 ms apart, stamped at publish, wall clock on receipt)
  and sustained GB/s (back to back, ``queue_size=None``), both CPUs placements;
* 3840x2160 rgb8 Image at 30 Hz: publisher + subscriber CPU as % of one core (process CPU time);
* 1 MB PointCloud2 back to back: messages delivered per second.

Implementations: ``ninjemys`` (SHMROS, ``publish`` copies the message into a slot),
``ninjemys-loan`` (``Publisher.loan``: the message's array is loaned from a slot and only the
fields around it are written; the image content is not rewritten per frame, as a camera driver that
captures straight into the loaned buffer), ``ninjemys-loan+fill`` (the same, plus a memcpy of a
prepared frame into every loan: a producer that has to copy anyway; one-way and 4K rows only),
``ninjemys-tcp`` (``NINJEMYS_SHM=0``), rospy and roscpp.

Targets (issue 25): one-way <= 1 ms, >= 5 GB/s, 4K CPU <= 10 %, PointCloud2 >= 3x rospy.
The roles live in this file (``node_shm.py role ARGS``) and use the rospy API, so the very same code
runs under ninjemys (the venv) and Debian's rospy; roscpp runs bench/node_shm_roscpp.py's program.
"""

from __future__ import annotations

import json
import os
import sys
import threading
import time

HD = (1920, 1080)
LOAN, LOAN_FILL = "ninjemys-loan", "ninjemys-loan+fill"
UHD = (3840, 2160)


def _pct(values: list[float], q: float) -> float:
    values = sorted(values)
    return values[min(len(values) - 1, int(q * len(values)))] if values else float("nan")


def _message(kind: str):  # noqa: ANN202
    from sensor_msgs.msg import Image, PointCloud2, PointField

    if kind == "cloud":
        n = (1 << 20) // 16
        fields = [PointField(name=c, offset=4 * i, datatype=7, count=1) for i, c in enumerate("xyzi")]
        msg = PointCloud2(height=1, width=n, fields=fields, point_step=16, row_step=16 * n, is_dense=True)
        msg.data = bytes(range(256)) * ((1 << 20) // 256)
        return PointCloud2, msg
    w, h = UHD if kind == "uhd" else HD
    return Image, Image(
        height=h, width=w, encoding="rgb8", step=w * 3, data=bytes(range(256)) * (w * h * 3 // 256)
    )


def _sender(pub, msg):  # noqa: ANN001, ANN202
    """``send(stamp)``: publish ``msg`` (stamped now when asked); with NINJEMYS_BENCH_LOAN set, a
    loaned message with ``msg``'s fields each time (``fill``: plus a copy of ``msg.data`` into it)."""
    import rospy

    loan = os.environ.get("NINJEMYS_BENCH_LOAN")
    if not loan:

        def send(stamp: bool) -> None:
            if stamp:
                msg.header.stamp = rospy.Time.from_sec(time.time())
            pub.publish(msg)

        return send
    impl = pub._impl  # the ninjemys Publisher behind rospy's (loan is ninjemys' own API)
    fields = {k: getattr(msg, k) for k in msg.__slots__ if k not in ("header", "data")}
    size = len(msg.data)
    frame = memoryview(msg.data)

    with impl.loan(size, **fields):  # warm up: numpy's import and the first loan are one-time costs
        pass

    def send_loaned(stamp: bool) -> None:
        with impl.loan(size, **fields) as m:
            if loan == "fill":
                m.data[:] = frame
            if stamp:
                m.header.stamp = rospy.Time.from_sec(time.time())
            pub.publish(m)

    return send_loaned


def role_pub(kind: str, mode: str, count: str) -> None:
    """mode: latency (count images 50 ms apart), flood (count back to back), rate30 (count seconds at 30 Hz)."""
    import rospy

    rospy.init_node("shm_pub")
    cls, msg = _message(kind)
    pub = rospy.Publisher("/big", cls, queue_size=None, tcp_nodelay=True)
    deadline = time.monotonic() + 30
    while pub.get_num_connections() < 1 and time.monotonic() < deadline:
        time.sleep(0.01)
    time.sleep(0.5)
    send = _sender(pub, msg)
    n = int(count)
    cpu0, wall0 = time.process_time(), time.monotonic()
    if mode == "latency":
        for _ in range(n):
            send(True)
            time.sleep(0.05)
    elif mode == "rate30":
        start = time.monotonic()
        i = 0
        while time.monotonic() - start < n:
            i += 1
            send(False)
            time.sleep(max(0.0, start + i / 30 - time.monotonic()))
    else:
        end = time.monotonic() + n
        while time.monotonic() < end:
            send(False)
    print(json.dumps({"cpu_s": time.process_time() - cpu0, "wall_s": time.monotonic() - wall0}), flush=True)
    time.sleep(2)
    rospy.signal_shutdown("done")


def role_sub(kind: str, mode: str, count: str) -> None:
    import rospy

    rospy.init_node("shm_sub")
    cls, _ = _message(kind)
    latencies: list[float] = []
    arrivals: list[tuple[float, int]] = []
    cpu: list[float] = []

    def cb(msg) -> None:  # noqa: ANN001
        now = time.time()
        if mode == "latency":
            latencies.append(now - msg.header.stamp.to_sec())
        else:
            arrivals.append((time.perf_counter(), len(msg.data)))
            if len(arrivals) == 1:
                cpu.append(time.process_time())

    rospy.Subscriber("/big", cls, cb, queue_size=None, buff_size=2**27, tcp_nodelay=True)
    print("ready", flush=True)
    # the window starts with the first message (a publisher under a loaded machine starts late)
    deadline = time.monotonic() + 120
    while not (latencies or arrivals) and time.monotonic() < deadline:
        time.sleep(0.01)
    time.sleep(float(count) * 0.05 + 2 if mode == "latency" else float(count) + 2)
    if mode == "latency":
        result = {"latency_ms": _pct(latencies, 0.5) * 1e3, "n": len(latencies)}
    else:
        span = arrivals[-1][0] - arrivals[0][0] if len(arrivals) > 1 else float("nan")
        result = {
            "n": len(arrivals),
            "per_s": (len(arrivals) - 1) / span if len(arrivals) > 1 else float("nan"),
            "gb_per_s": sum(b for _, b in arrivals[1:]) / span / 1e9 if len(arrivals) > 1 else float("nan"),
            "cpu_s": time.process_time() - cpu[0] if cpu else float("nan"),
            "span_s": span,
        }
    print(json.dumps(result), flush=True)
    rospy.signal_shutdown("done")


# -- the driver ----------------------------------------------------------------------------------


def _run(impl: str, uri: str, kind: str, mode: str, count: str, cpus: tuple[str, str]) -> dict:
    import node_shm_roscpp
    from ninjemys.testing import ROS1_PYTHON, ros1_env
    from node_common import CPP, OURS, roles

    def spawn(side: str, cpu: str):  # noqa: ANN202
        args = [side, kind, mode, count]
        if impl == CPP:
            return _spawn([str(node_shm_roscpp.binary()), *args], ros1_env(uri), cpu)
        if impl.startswith(OURS):
            env = dict(os.environ, ROS_MASTER_URI=uri, ROS_HOSTNAME="localhost")
            env["NINJEMYS_SHM"] = "0" if impl == "ninjemys-tcp" else "1"
            env["NINJEMYS_BENCH_LOAN"] = {LOAN: "1", LOAN_FILL: "fill"}.get(impl, "")
            return _spawn([sys.executable, os.path.abspath(__file__), *args], env, cpu)
        return _spawn([ROS1_PYTHON, os.path.abspath(__file__), *args], ros1_env(uri), cpu)

    sub = spawn("sub", cpus[1])
    with roles(sub):
        sub.ready()
        with roles(spawn("pub", cpus[0])) as (pub,):
            got = sub.result(timeout=300)
            sent = pub.result(timeout=60)
    got["pub_cpu_s"] = sent["cpu_s"]
    got["pub_wall_s"] = sent["wall_s"]
    return got


def _spawn(cmd: list[str], env: dict[str, str], cpu: str):  # noqa: ANN202
    """A node_common.Role for any command line (the roles of this file, or the roscpp program)."""
    import subprocess
    import tempfile

    from node_common import Role

    role = Role.__new__(Role)
    env = dict(env, ROS_HOME=tempfile.mkdtemp(prefix="bench_node_home_"))
    role.proc = subprocess.Popen(
        ["taskset", "-c", cpu, *cmd], env=env, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL
    )
    role.lines = []
    role._cond = threading.Condition()
    role._thread = threading.Thread(target=role._read, daemon=True)
    role._thread.start()
    return role


def _ratios(what: str, values: dict[str, float], ours: list[str]) -> None:
    """One line per implementation of ours: its value over rospy's and roscpp's (lower is better)."""
    from node_common import CPP, REAL

    for impl in ours:
        parts = [f"/{ref} {values[impl] / values[ref]:.3f}x" for ref in (REAL, CPP) if values.get(ref)]
        if parts and impl in values:
            print(f"{what}: {impl} {', '.join(parts)}", flush=True)


def main() -> None:
    sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
    import node_shm_roscpp
    from node_common import CPP, CROSS_CPU, OURS, REAL, SAME_CPU, header, master

    seconds = sys.argv[1] if len(sys.argv) > 1 else "5"
    impls = [OURS, LOAN, LOAN_FILL, "ninjemys-tcp"]
    from ninjemys.testing import have_ros1

    if have_ros1():
        impls.append(REAL)
        if node_shm_roscpp.binary():
            impls.append(CPP)
    header(f"large messages on one host: {', '.join(impls)}; {seconds} s per stream")
    rows: list[str] = []
    with master() as uri:
        for place, cpus in (("one CPU", SAME_CPU), ("across CPUs", CROSS_CPU)):
            oneway: dict[str, float] = {}
            for impl in impls:
                lat = _run(impl, uri, "hd", "latency", "30", cpus)
                oneway[impl] = lat["latency_ms"]
                row = f"1080p rgb8 {place:11s} {impl:18s} one-way p50 {lat['latency_ms']:7.2f} ms"
                if impl != LOAN_FILL:
                    flood = _run(impl, uri, "hd", "flood", seconds, cpus)
                    row += f"   sustained {flood['gb_per_s']:6.2f} GB/s ({flood['per_s']:6.1f} img/s)"
                    if impl == LOAN:
                        row += " (the image is not rewritten per frame: GB/s the subscriber could read)"
                rows.append(row)
                print(rows[-1], flush=True)
            _ratios(f"1080p one-way {place}", oneway, [LOAN, OURS])
        cpus_4k: dict[str, float] = {}
        for impl in impls:
            r = _run(impl, uri, "uhd", "rate30", seconds, CROSS_CPU)
            cpu = (r["pub_cpu_s"] / r["pub_wall_s"] + r["cpu_s"] / r["span_s"]) * 100
            cpus_4k[impl] = cpu
            rows.append(
                f"4K rgb8 30 Hz  across CPUs {impl:18s} pub+sub CPU {cpu:6.1f} % of one core ({r['per_s']:.1f} Hz)"
            )
            print(rows[-1], flush=True)
        _ratios("4K 30 Hz CPU", cpus_4k, [LOAN, OURS])
        clouds = {}
        for impl in impls:
            if impl == LOAN_FILL:
                continue
            r = _run(impl, uri, "cloud", "flood", seconds, CROSS_CPU)
            clouds[impl] = r["per_s"]
            rows.append(f"PointCloud2 1 MB across CPUs {impl:18s} delivered {r['per_s']:8.1f} msg/s")
            print(rows[-1], flush=True)
        if REAL in clouds:
            print(f"PointCloud2 ratio ninjemys/rospy {clouds[OURS] / clouds[REAL]:.2f}x", flush=True)
    print(f"load average {os.getloadavg()}")


if __name__ == "__main__":
    if len(sys.argv) > 1 and sys.argv[1] in ("pub", "sub"):
        (role_pub if sys.argv[1] == "pub" else role_sub)(*sys.argv[2:5])
    else:
        main()

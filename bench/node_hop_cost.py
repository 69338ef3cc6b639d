"""What one hop of a small-message ping-pong costs the pong process, counted rather than timed: system
calls per message (``strace -c``), wake-ups (voluntary context switches) per message for each of its
threads, CPU time per message and, with ``--callgrind``, user-space instructions per message. Counts
hold on a loaded machine where latencies do not (the machine is shared), so this is the before/after
evidence for a change of the receive path; ``bench/node_rtt.py`` gives the latencies.

Run: ``.venv/bin/python bench/node_hop_cost.py [--count N] [--compare SRC] [--callgrind]``: both
roles are ours (bench/node_roles.py ``ping``/``pong``, ``queue_size=10``, one CPU); ``--compare SRC``
runs the same with ``SRC`` (a ``src`` directory, e.g. of ``git archive main``) first on the path, side
by side; each side's counts come from a window that opens after the pong has started and closes when
the ping has its result (its connection set-up, a few dozen calls, is inside it).
"""

from __future__ import annotations

import argparse
import os
import re
import shutil
import signal
import subprocess
import tempfile
import time
from pathlib import Path

from node_common import OURS, SAME_CPU, Role, header, master, roles

HERE = str(Path(__file__).resolve().parents[1] / "src")


def thread_stats(pid: int) -> dict[str, tuple[int, float]]:
    """Per thread (``main`` or ``t<n>`` in the order of their ids): (voluntary context switches, CPU
    seconds from ``schedstat``, which counts nanoseconds, where ``stat``'s ticks are 10 ms)."""
    out: dict[str, tuple[int, float]] = {}
    tasks = sorted(Path(f"/proc/{pid}/task").iterdir(), key=lambda t: int(t.name))
    for index, task in enumerate(tasks):
        try:
            status = (task / "status").read_text()
            ran = int((task / "schedstat").read_text().split()[0]) / 1e9
        except OSError:
            continue
        found = re.search(r"^voluntary_ctxt_switches:\s*(\d+)", status, re.M)
        name = "main" if task.name == str(pid) else f"t{index}"
        out[f"{name}({_SYSCALLS.get(_syscall(task), 'other')})"] = (int(found.group(1)) if found else 0, ran)
    return out


#: x86_64 system calls a thread of a node sleeps in, to tell the threads apart (they are all "python")
_SYSCALLS = {"45": "recvfrom", "232": "epoll_wait", "202": "futex", "7": "poll", "23": "select", "0": "read"}


def _syscall(task: Path) -> str:
    try:
        return (task / "syscall").read_text().split()[0]
    except (OSError, IndexError):
        return ""


def strace_attach(pid: int, path: str) -> subprocess.Popen:
    proc = subprocess.Popen(
        ["strace", "-c", "-f", "-o", path, "-p", str(pid)],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    time.sleep(1.0)  # attached to every thread
    return proc


def strace_table(path: str, messages: int) -> dict[str, float]:
    """System call -> calls per message, from ``strace -c``'s table."""
    calls: dict[str, float] = {}
    for line in Path(path).read_text().splitlines():
        parts = line.split()
        if len(parts) >= 5 and parts[0][0].isdigit() and not line.startswith("100.00"):
            name = parts[-1]
            count = int(parts[3])
            calls[name] = count / messages
    return calls


def one_side(uri: str, src: str, count: int, mode: str) -> dict[str, object]:
    """Run a ping-pong with ``src`` first on the path and count the pong's costs in ``mode``
    (``stats``: wake-ups and CPU; ``strace``; ``callgrind``)."""
    os.environ["PYTHONPATH"] = src
    messages = count + 200  # the ping's warm-up round trips are inside the window too
    result: dict[str, object] = {}
    if mode == "callgrind":
        out = tempfile.mktemp(prefix="hop_cost_", suffix=".callgrind")
        pong = Role(OURS, uri, "pong", "10", cpu=SAME_CPU[1])
        pong.proc.kill()  # replaced by the same role under callgrind, instrumentation off until asked
        pong.proc.wait()
        import sys

        import node_common

        cmd = [
            "taskset", "-c", SAME_CPU[1], "valgrind", "--tool=callgrind", "--instr-atstart=no",
            f"--callgrind-out-file={out}", sys.executable, node_common.ROLES, "pong", "10",
        ]  # fmt: skip
        env = dict(os.environ, ROS_MASTER_URI=uri, ROS_HOSTNAME="localhost")
        proc = subprocess.Popen(cmd, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        try:
            time.sleep(20.0)  # Python's start-up under valgrind
            subprocess.run(["callgrind_control", "-i", "on", str(proc.pid)], capture_output=True, check=False)
            ping = Role(OURS, uri, "ping", str(count), "10", cpu=SAME_CPU[0])
            with roles(ping):
                ping.result(timeout=600)
            subprocess.run(
                ["callgrind_control", "-i", "off", str(proc.pid)], capture_output=True, check=False
            )
        finally:
            proc.send_signal(signal.SIGINT)
            proc.wait(60)
        text = Path(out).read_text(errors="replace")
        total = re.search(r"^totals:\s*(\d+)", text, re.M)
        result["instructions"] = int(total.group(1)) / messages if total else float("nan")
        return result
    with roles(Role(OURS, uri, "pong", "10", cpu=SAME_CPU[1])) as (pong,):
        time.sleep(3.0)  # the pong is up and registered
        pid = pong.proc.pid
        # taskset execs the interpreter: the role's pid is the interpreter's
        tracer = None
        trace_out = tempfile.mktemp(prefix="hop_cost_", suffix=".strace")
        if mode == "strace":
            tracer = strace_attach(pid, trace_out)
        before = thread_stats(pid)
        ping = Role(OURS, uri, "ping", str(count), "10", cpu=SAME_CPU[0])
        with roles(ping):
            got = ping.result(timeout=600)
        after = thread_stats(pid)
        if tracer is not None:
            tracer.send_signal(signal.SIGINT)
            tracer.wait(30)
            result["syscalls"] = strace_table(trace_out, messages)
        else:
            result["p50_us"] = got["p50_us"]
        result["threads"] = {
            name: ((after[name][0] - before.get(name, (0, 0.0))[0]) / messages,
                   (after[name][1] - before.get(name, (0, 0.0))[1]) / messages * 1e6)
            for name in after
        }  # fmt: skip
    return result


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--count", type=int, default=3000)
    parser.add_argument("--rounds", type=int, default=2, help="interleaved rounds of the wake-up/CPU count")
    parser.add_argument("--compare", metavar="SRC", help="another tree's src directory, run side by side")
    parser.add_argument("--callgrind", action="store_true", help="also user-space instructions per message")
    opts = parser.parse_args()
    sides = [("this tree", HERE)] + ([("compare", opts.compare)] if opts.compare else [])
    header(f"cost of one hop in the pong of a ping-pong, {opts.count} round trips, one CPU, queue_size=10")
    keep = os.environ.get("PYTHONPATH")
    try:
        with master() as uri:
            for name, src in sides if shutil.which("strace") else ():  # (Debian's strace)
                got = one_side(uri, src, opts.count, "strace")
                calls = got["syscalls"]
                assert isinstance(calls, dict)
                total = sum(calls.values())
                listed = ", ".join(
                    f"{k} {v:.2f}" for k, v in sorted(calls.items(), key=lambda kv: -kv[1]) if v >= 0.01
                )
                print(f"{name:10s} system calls per message {total:5.2f}: {listed}")
            for round_ in range(opts.rounds):
                for name, src in sides if round_ % 2 == 0 else sides[::-1]:
                    got = one_side(uri, src, opts.count, "stats")
                    threads = got["threads"]
                    assert isinstance(threads, dict)
                    listed = ", ".join(
                        f"{t} {w:.2f} wake-ups {c:.1f} us"
                        for t, (w, c) in sorted(threads.items())
                        if w >= 0.01 or c >= 0.5
                    )
                    cpu = sum(c for _, c in threads.values())
                    print(
                        f"{name:10s} round {round_ + 1} (load {os.getloadavg()[0]:.1f}): RTT p50 {got['p50_us']:6.1f} us,"
                        f" pong CPU {cpu:5.1f} us per message; per thread: {listed}"
                    )
            if opts.callgrind and shutil.which("valgrind"):
                for name, src in sides:
                    got = one_side(uri, src, opts.count, "callgrind")
                    print(
                        f"{name:10s} user-space instructions per message (callgrind): {got['instructions']:,.0f}"
                    )
    finally:
        if keep is None:
            os.environ.pop("PYTHONPATH", None)
        else:
            os.environ["PYTHONPATH"] = keep


if __name__ == "__main__":
    main()

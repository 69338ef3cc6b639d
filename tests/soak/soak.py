"""The soak: 50 nodes under load, random SIGKILLs, two master restarts, a bag recording throughout.

    .venv/bin/python tests/soak/soak.py --duration 600     # the long form (make soak)
    .venv/bin/python tests/soak/soak.py --duration 45      # about the short form tests/soak runs

Layout: our roscore; ``--hosts`` long-lived worker processes holding most nodes (they survive and are
watched for leaks); ``--singles`` one-node processes that are SIGKILLed at random and respawned at
once under the same name; ``rosbag record`` (ours) on every soak topic from start to end, stopped with
SIGINT; and a second recorder SIGKILLed mid-run, whose ``.bag.active`` must reindex.

After every fault the soak waits for the graph to heal, polling from outside over XML-RPC only:
  - every node is registered and its URI answers ``getPid`` with the pid of its live process;
  - the master lists every publisher, subscriber and service provider of the plan;
  - every subscriber (the recorder too) holds a connected inbound link from the live URI of each
    publisher of its topics (its ``getBusInfo``);
  - every service answers a TCPROS probe with the header of its live provider.
Heal time runs from the fault's repair (the respawned process started; the new master answering)
to the first poll that sees all of that. Polls take ~0.1-0.4 s, the resolution of the figures.

Resources (RSS, open fds, threads) of the surviving processes are sampled after the first heal
(plus a warm-up) and at the end; each master's after its heal (plus the same warm-up) and just before
it is killed (or at the end). The bounds are in :data:`TOLERANCE`.

Acknowledged messages: the recorder stopped with SIGINT closes its bag and prints ``Recorded N
messages``; the bag must be readable and hold exactly N, and each publisher incarnation's messages
must be gap-free after its first (TCP does not lose within a connection; the recorder's queue does
not drop at this load, and says so when it does). The SIGKILLed recorder acknowledged what its last
``--stats`` line counted at least 2 s before the kill (its writer puts every chunk on disk within
1 s); its reindexed bag must hold at least that many.
"""

from __future__ import annotations

import argparse
import json
import os
import random
import re
import signal
import statistics
import subprocess
import sys
import tempfile
import time
from collections import defaultdict
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from ninjemys import testing
from ninjemys.errors import NinjemysError
from ninjemys.net import auth
from ninjemys.node.services import probe

HERE = Path(__file__).resolve().parent
WORKER = HERE / "worker.py"
TYPES = ("std_msgs/String", "geometry_msgs/Twist", "sensor_msgs/LaserScan")

#: start-vs-end bounds for the survivors and the masters: (fds, threads) may grow by at most this
#: many; RSS by at most RSS_FACTOR x start + RSS_SLACK_MB (Python's allocator keeps some arenas).
TOLERANCE = {"fds": 4, "threads": 2}
#: A master's asyncio loop resolves peers' host names on asyncio's default executor, a pool that
#: grows on demand to min(32, CPUs + 4) threads and keeps them (seen in the soak: asyncio_0..5 on
#: 2 CPUs); that many more threads are allowed for a master, a bound, not a leak.
MASTER_POOL = min(32, (os.cpu_count() or 1) + 4)
RSS_FACTOR, RSS_SLACK_MB = 1.10, 8.0


class SoakFailure(NinjemysError, AssertionError):
    """The soak saw something wrong (a graph that did not heal, a leak, a bag short of messages)."""


# -- the plan ----------------------------------------------------------------------------------------


@dataclass
class NodePlan:
    name: str
    pub: list[list[str]] = field(default_factory=list)
    sub: list[list[str]] = field(default_factory=list)
    srv: list[str] = field(default_factory=list)
    call: list[str] = field(default_factory=list)


def make_plan(
    nodes: int, singles: int, hosts: int, topics: int, services: int, seed: int
) -> list[list[NodePlan]]:
    """``hosts`` groups of long-lived nodes then ``singles`` one-node groups; topics and services are
    spread over both, so killing a single kills publishers, subscribers, servers and callers."""
    rng = random.Random(seed)
    plans = [NodePlan(f"/soak/n{i:02d}") for i in range(nodes)]
    topic_list = [(f"/soak/t{k}", TYPES[k % len(TYPES)]) for k in range(topics)]
    single_idx = list(range(nodes - singles, nodes))
    host_idx = list(range(nodes - singles))
    for k, topic in enumerate(topic_list):
        # half the topics from killable singles, half from survivors
        owner = single_idx[k % len(single_idx)] if k % 2 else host_idx[k % len(host_idx)]
        plans[owner].pub.append(list(topic))
    for plan in plans:
        mine = {t for t, _ in plan.pub}
        choices = [t for t in topic_list if t[0] not in mine]
        plan.sub = [list(t) for t in rng.sample(choices, 2)]
    for k in range(services):
        owner = single_idx[(k * 3 + 1) % len(single_idx)] if k % 2 else host_idx[(k * 5 + 2) % len(host_idx)]
        plans[owner].srv.append(f"/soak/s{k}")
    for k in range(services * 2):
        caller = (k * 7 + 3) % nodes
        name = f"/soak/s{k % services}"
        if name not in plans[caller].srv:
            plans[caller].call.append(name)
    groups: list[list[NodePlan]] = [[] for _ in range(hosts)]
    for i in host_idx:
        groups[i % hosts].append(plans[i])
    return groups + [[plans[i]] for i in single_idx]


# -- processes --------------------------------------------------------------------------------------


def proc_stats(pid: int) -> dict[str, float]:
    """RSS (MB), open file descriptors and threads of a live process, from /proc."""
    status = Path(f"/proc/{pid}/status").read_text()
    rss = int(re.search(r"VmRSS:\s+(\d+)", status).group(1)) / 1024  # type: ignore[union-attr]
    threads = int(re.search(r"Threads:\s+(\d+)", status).group(1))  # type: ignore[union-attr]
    fds = len(os.listdir(f"/proc/{pid}/fd"))
    return {"rss": rss, "fds": fds, "threads": threads}


class Worker:
    """One worker process and the nodes it holds."""

    def __init__(
        self, group: list[NodePlan], rate: float, env: dict[str, str], workdir: Path, tag: str
    ) -> None:
        self.group, self.rate, self.env, self.tag = group, rate, env, tag
        self.spec = workdir / f"{tag}.json"
        self.spec.write_text(json.dumps({"rate": rate, "nodes": [p.__dict__ for p in group]}))
        self.proc: testing.NodeProcess | None = None
        self.incarnations = 0
        self.start()

    def start(self) -> None:
        self.proc = testing.NodeProcess([sys.executable, str(WORKER), str(self.spec)], env=self.env)
        self.incarnations += 1

    def wait_up(self, timeout: float = 60.0) -> None:
        assert self.proc is not None
        self.proc.wait_for(r"^up$", timeout=timeout)

    @property
    def pid(self) -> int:
        assert self.proc is not None
        return self.proc.pid

    def sigkill(self) -> None:
        assert self.proc is not None
        self.proc.kill()

    def terminate(self) -> None:
        """SIGTERM without waiting, so that all workers shut their nodes down at once."""
        if self.proc is not None and self.proc.proc.poll() is None:
            self.proc.proc.terminate()

    def stop(self) -> None:
        if self.proc is not None:
            self.proc.stop(grace=10.0)

    def last_stats(self) -> dict[str, int]:
        assert self.proc is not None
        for line in reversed(self.proc.text().splitlines()):
            if line.startswith("stats "):
                return {k: int(v) for k, v in (kv.split("=") for kv in line.split()[1:])}
        return {}


class Master:
    """Our roscore on a fixed port, killed and restarted by the soak."""

    def __init__(self, port: int, env: dict[str, str]) -> None:
        self.port, self.env = port, env
        self.uri = f"http://localhost:{port}/"
        self.proc: subprocess.Popen[bytes] | None = None

    def start(self, timeout: float = 30.0) -> float:
        """Start it and wait until it answers; returns the monotonic time it first answered."""
        self.proc = subprocess.Popen(
            [testing.ninjemys_bin("roscore"), "-p", str(self.port)],
            env=self.env,
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
            stdin=subprocess.DEVNULL,
        )
        deadline = time.monotonic() + timeout
        while True:
            try:
                auth.server_proxy(self.uri).getPid("/soak")
                return time.monotonic()
            except OSError:
                if self.proc.poll() is not None or time.monotonic() > deadline:
                    raise SoakFailure(
                        f"roscore -p {self.port} did not come up (exit {self.proc.poll()})"
                    ) from None
                time.sleep(0.02)

    def sigkill(self) -> None:
        if self.proc is not None:
            testing.kill_tree(self.proc)

    @property
    def pid(self) -> int:
        assert self.proc is not None
        return self.proc.pid


# -- the heal check ------------------------------------------------------------------------------


class Graph:
    """What the soak expects of the graph, and one poll of whether it holds (XML-RPC only)."""

    def __init__(self, master: Master, workers: list[Worker]) -> None:
        self.master, self.workers = master, workers
        self.recorder_topics: list[str] = []
        self.recorder_pids: list[int] = []
        self.last_problem = ""

    def _rpc(self, uri: str) -> Any:
        return auth.server_proxy(uri)

    def check(self) -> bool:
        try:
            problem = self._problem()
        except (OSError, NinjemysError, ValueError) as exc:  # a poll racing a restart: not healed yet
            problem = f"{type(exc).__name__}: {exc}"
        self.last_problem = problem
        return problem == ""

    def _problem(self) -> str:
        master = self._rpc(self.master.uri)
        code, _, state = master.getSystemState("/soak")
        if code != 1:
            return "getSystemState failed"
        pubs = {t: set(n) for t, n in state[0]}
        subs = {t: set(n) for t, n in state[1]}
        srvs = {s: set(n) for s, n in state[2]}
        uris: dict[str, str] = {}
        for w in self.workers:
            for plan in w.group:
                code, msg, uri = master.lookupNode("/soak", plan.name)
                if code != 1:
                    return f"{plan.name} not registered ({msg})"
                code, _, pid = self._rpc(uri).getPid("/soak")
                if pid != w.pid:
                    return f"{plan.name} at {uri} is pid {pid}, not the live {w.pid}"
                uris[plan.name] = uri
                for topic, _ in plan.pub:
                    if plan.name not in pubs.get(topic, ()):
                        return f"master does not list {plan.name} as a publisher of {topic}"
                for topic, _ in plan.sub:
                    if plan.name not in subs.get(topic, ()):
                        return f"master does not list {plan.name} as a subscriber of {topic}"
                for name in plan.srv:
                    if plan.name not in srvs.get(name, ()):
                        return f"master does not list {plan.name} as the provider of {name}"
        publisher = {t: p.name for w in self.workers for p in w.group for t, _ in p.pub}
        links: list[tuple[str, str, str]] = [
            (uris[p.name], topic, uris[publisher[topic]])
            for w in self.workers
            for p in w.group
            for topic, _ in p.sub
        ]
        recorders: dict[int, tuple[str, str]] = {}  # pid -> name, URI of each live recorder the master knows
        for name in {n for t in self.recorder_topics for n in subs.get(t, ()) if n.startswith("/record_")}:
            code, _, uri = master.lookupNode("/soak", name)
            if code == 1:
                try:
                    recorders[self._rpc(uri).getPid("/soak")[2]] = (name, uri)
                except OSError:
                    continue  # a killed recorder the master still lists
        for pid in self.recorder_pids:
            if pid not in recorders:
                return f"the recorder (pid {pid}) is not registered"
            name, uri = recorders[pid]
            for topic in self.recorder_topics:
                if name not in subs.get(topic, ()):
                    return f"master does not list the recorder {name} as a subscriber of {topic}"
                links.append((uri, topic, uris[publisher[topic]]))
        bus: dict[str, list[Any]] = {}
        for sub_uri, topic, pub_uri in links:
            if sub_uri not in bus:
                bus[sub_uri] = self._rpc(sub_uri).getBusInfo("/soak")[2]
            if not any(c[2] == "i" and c[4] == topic and c[1] == pub_uri and c[5] for c in bus[sub_uri]):
                return f"subscriber {sub_uri} has no live link on {topic} from {pub_uri}"
        for w in self.workers:
            for plan in w.group:
                for name in plan.srv:
                    code, msg, srv_uri = master.lookupService("/soak", name)
                    if code != 1:
                        return f"{name} not found ({msg})"
                    reply = probe(name, srv_uri, timeout=2.0, caller_id="/soak")
                    if reply.get("callerid") != plan.name:
                        return f"{name} answered by {reply.get('callerid')}, not {plan.name}"
        return ""

    def wait_healed(self, since: float, timeout: float, what: str) -> float:
        """Seconds from ``since`` until the graph is whole again; SoakFailure after ``timeout``."""
        deadline = time.monotonic() + timeout
        while True:
            if self.check():
                return time.monotonic() - since
            if time.monotonic() > deadline:
                raise SoakFailure(
                    f"the graph did not heal within {timeout:g} s after {what}: {self.last_problem}"
                )
            time.sleep(0.05)


# -- the bag -----------------------------------------------------------------------------------------


def recorder_cmd(path: Path, topics: list[str]) -> list[str]:
    return [testing.ninjemys_bin("rosbag"), "record", "--stats", "1", "-O", str(path), *topics]


def read_bag(path: Path) -> dict[str, dict[int, list[int]]]:
    """topic -> publisher pid -> sequence numbers, in bag order."""
    from ninjemys.bag.api import Bag

    sys.path.insert(0, str(HERE))
    from worker import identity  # the worker's own decoding of (pid, seq)

    found: dict[str, dict[int, list[int]]] = defaultdict(lambda: defaultdict(list))
    with Bag(str(path)) as bag:
        for topic, msg, _t in bag.read_messages():
            pid, seq = identity(msg._type, msg)
            found[topic][pid].append(seq)
    return found


def check_streams(found: dict[str, dict[int, list[int]]]) -> list[str]:
    """Holes in the middle of an incarnation's stream (a stream may start late: connection set-up)."""
    holes = []
    for topic, by_pid in sorted(found.items()):
        for pid, seqs in by_pid.items():
            if seqs != list(range(seqs[0], seqs[0] + len(seqs))):
                missing = sorted(set(range(seqs[0], seqs[-1] + 1)) - set(seqs))
                holes.append(
                    f"{topic} pid {pid}: {len(missing)} missing of {seqs[0]}..{seqs[-1]}, e.g. {missing[:5]}"
                )
    return holes


def recorded_count(text: str) -> int:
    counts = [int(m.group(1)) for m in re.finditer(r"Recorded (\d+) messages", text)]
    if not counts:
        raise SoakFailure(f"the recorder printed no 'Recorded N messages' line:\n{text[-1000:]}")
    return counts[-1]


# -- the run -------------------------------------------------------------------------------------------


def percentile(values: list[float], q: float) -> float:
    ordered = sorted(values)
    return ordered[min(len(ordered) - 1, max(0, round(q * (len(ordered) - 1))))]


def summarize(values: list[float]) -> dict[str, float]:
    if not values:
        return {}
    return {
        "n": len(values),
        "p50": statistics.median(values),
        "p95": percentile(values, 0.95),
        "max": max(values),
    }


def run_soak(
    duration: float = 60.0,
    nodes: int = 50,
    singles: int = 14,
    hosts: int = 3,
    topics: int = 10,
    services: int = 5,
    rate: float = 5.0,
    seed: int = 1,
    port: int | None = None,
    workdir: Path | None = None,
    log: Any = print,
) -> dict[str, Any]:
    """Run the soak for about ``duration`` seconds of faults; returns the report (raises SoakFailure)."""
    rng = random.Random(seed)
    tmp = tempfile.TemporaryDirectory(prefix="ninjemys_soak_") if workdir is None else None
    work = Path(tmp.name) if tmp is not None else Path(workdir or ".")
    work.mkdir(parents=True, exist_ok=True)
    port = port or testing.free_port()
    env = {k: v for k, v in os.environ.items() if not k.startswith("ROS_") and k != "NINJEMYS_SECRET"}
    env.update(ROS_MASTER_URI=f"http://localhost:{port}/", ROS_HOSTNAME="localhost", ROS_HOME=str(work),
               ROS_LOG_DIR=str(work / "log"), PYTHONUNBUFFERED="1")  # fmt: skip
    report: dict[str, Any] = {"nodes": nodes, "duration": duration, "seed": seed, "rate": rate}
    master = Master(port, env)
    workers: list[Worker] = []
    recorders: list[testing.NodeProcess] = []
    topic_names = [f"/soak/t{k}" for k in range(topics)]
    heal: dict[str, list[float]] = {"node_kill": [], "master_restart": [], "master_restart_from_kill": []}
    try:
        master.start()
        groups = make_plan(nodes, singles, hosts, topics, services, seed)
        workers = [Worker(g, rate, env, work, f"w{i}") for i, g in enumerate(groups)]
        bag_path, killed_path = work / "soak.bag", work / "killed.bag"
        recorders = [
            testing.NodeProcess(recorder_cmd(p, topic_names), env=env) for p in (bag_path, killed_path)
        ]
        for w in workers:
            w.wait_up()
        graph = Graph(master, workers)
        graph.recorder_topics = topic_names
        graph.recorder_pids = [r.pid for r in recorders]
        t0 = time.monotonic()
        report["initial_heal_s"] = graph.wait_healed(t0, 120.0, "start-up")
        # the recorders: both subscribed; from now on only the first must stay whole
        graph.recorder_pids = [recorders[0].pid]
        time.sleep(3.0)  # warm-up: every connection made, caches filled
        survivors = {f"worker {w.tag}": w.pid for w in workers[:hosts]} | {"recorder": recorders[0].pid}
        start_res = {name: proc_stats(pid) for name, pid in survivors.items()}
        start_res["master 1"] = proc_stats(master.pid)
        end_res: dict[str, dict[str, float]] = {}
        log(f"healed at start in {report['initial_heal_s']:.2f} s; resources {start_res}")

        begin = time.monotonic()
        restarts_at = [begin + duration / 3, begin + 2 * duration / 3]
        kill_recorder_at = begin + duration / 2
        recorder_ack = 0
        kills = 0
        series: list[dict[str, float]] = []  # survivors' RSS (MB) about every tenth of the run: the trend
        next_sample = begin + duration / 10
        while time.monotonic() - begin < duration:
            now = time.monotonic()
            if restarts_at and now >= restarts_at[0]:
                restarts_at.pop(0)
                incarnation = 3 - len(restarts_at)
                end_res[f"master {incarnation - 1}"] = proc_stats(master.pid)
                down = time.monotonic()
                master.sigkill()
                time.sleep(rng.uniform(0.5, 2.0))  # the graph runs master-less for a while
                back = master.start()
                took = graph.wait_healed(back, 60.0, "a master restart")
                heal["master_restart"].append(took)
                heal["master_restart_from_kill"].append(back + took - down)
                log(
                    f"master restart: healed {took:.2f} s after it answered ({back + took - down:.2f} s after the kill)"
                )
                time.sleep(2.0)  # the same warm-up as the first master's
                start_res[f"master {incarnation}"] = proc_stats(master.pid)
                continue
            if recorders[1].proc.poll() is None and now >= kill_recorder_at:
                recorder_ack = _stats_before(recorders[1], time.time() - 2.0)
                recorders[1].kill()
                log(f"recorder 2 SIGKILLed; it had acknowledged {recorder_ack} messages 2 s before")
                continue
            victims = rng.sample(workers[hosts:], rng.choice((1, 1, 2)))
            for w in victims:
                w.sigkill()
            time.sleep(rng.uniform(0.0, 0.5))
            respawn = time.monotonic()
            for w in victims:
                w.start()
            kills += len(victims)
            took = graph.wait_healed(respawn, 60.0, f"SIGKILL of {[w.group[0].name for w in victims]}")
            heal["node_kill"].append(took)
            if time.monotonic() >= next_sample:
                next_sample += duration / 10
                series.append(
                    {"t": round(time.monotonic() - begin, 1)}
                    | {n: proc_stats(p)["rss"] for n, p in survivors.items()}
                )
            time.sleep(rng.uniform(0.5, 2.0))
        report["kills"] = kills
        if os.environ.get("SOAK_TRACE_MEMORY"):
            os.kill(workers[0].pid, signal.SIGUSR1)
            time.sleep(3.0)
            assert workers[0].proc is not None
            log("\n".join(line for line in workers[0].proc.text().splitlines() if line.startswith("TM")))
        report["master_restarts"] = len(heal["master_restart"])
        time.sleep(2.0)
        end_res |= {name: proc_stats(pid) for name, pid in survivors.items()}
        end_res[f"master {1 + len(heal['master_restart'])}"] = proc_stats(master.pid)
        report["resources"] = {"start": start_res, "end": end_res, "rss_series": series}
        report["leaks"] = leaks(start_res, end_res)
        stats = [w.last_stats() for w in workers]
        report["service_calls_ok"] = sum(s.get("calls_ok", 0) for s in stats)
        report["service_calls_failed"] = sum(s.get("calls_failed", 0) for s in stats)
        # stop the recorder as a user does, then the workers
        recorders[0].interrupt()
        code = recorders[0].wait(60.0)
        if code != 0:
            raise SoakFailure(f"rosbag record exited with {code}: {recorders[0].describe()}")
        acknowledged = recorded_count(recorders[0].text())
        found = read_bag(bag_path)
        in_bag = sum(len(s) for by_pid in found.values() for s in by_pid.values())
        report["bag"] = {"acknowledged": acknowledged, "in_bag": in_bag, "holes": check_streams(found),
                         "topics": len(found), "incarnations": sum(len(v) for v in found.values())}  # fmt: skip
        report["killed_bag"] = killed_bag(killed_path, recorder_ack)
    finally:
        for r in recorders:
            r.kill()
        for w in workers:
            w.terminate()
        for w in workers:
            w.stop()
        master.sigkill()
        if tmp is not None:
            tmp.cleanup()
    report["heal"] = {k: summarize(v) for k, v in heal.items()}
    report["heal_raw"] = heal
    return report


def _stats_before(recorder: testing.NodeProcess, wall: float) -> int:
    """The message count of the recorder's last ``--stats`` line printed before wall time ``wall``."""
    best = 0
    for line in recorder.text().splitlines():
        m = re.match(r"\[ INFO\] \[([\d.]+)\]: Recorded (\d+) messages", line)
        if m and float(m.group(1)) <= wall:
            best = int(m.group(2))
    return best


def killed_bag(path: Path, acknowledged: int) -> dict[str, Any]:
    """Reindex the SIGKILLed recorder's ``.bag.active`` with our ``rosbag reindex`` and count it."""
    active = path.with_name(path.name + ".active")
    if not active.exists():
        raise SoakFailure(f"the killed recorder left no {active.name}")
    done = subprocess.run([testing.ninjemys_bin("rosbag"), "reindex", str(active)],
                          capture_output=True, text=True, timeout=120)  # fmt: skip
    if done.returncode != 0:
        raise SoakFailure(f"rosbag reindex {active.name} failed: {done.stderr.strip()}")
    found = read_bag(active)
    return {"acknowledged": acknowledged, "in_bag": sum(len(s) for v in found.values() for s in v.values()),
            "holes": check_streams(found)}  # fmt: skip


def cut_link_heals(rounds: int = 5, cut_s: float = 2.0) -> list[float] | str:
    """Seconds from restoring a cut link until the stream across it resumes, ``rounds`` times; or why
    it cannot be measured here (network namespaces need root: tests/multihost/netns.py).

    Three hosts as in tests/multihost: the master on hosta, a talker (20 Hz) on hostb, a listener on
    hostc; hostb's link is cut for ``cut_s`` seconds, then restored. What comes back is TCP's
    retransmission (its back-off after a silence of ``cut_s``) plus nothing of ours: the connection
    was never torn down.
    """
    sys.path.insert(0, str(HERE.parent))
    from multihost.netns import Network, unavailable

    why = unavailable()
    if why is not None:
        return why
    node = [sys.executable, str(HERE.parent / "multihost" / "node_proc.py")]
    venv_bin = Path(sys.executable).parent
    net = Network()
    healed: list[float] = []
    try:

        def env(host: str) -> dict[str, str]:
            out = {k: v for k, v in os.environ.items() if not k.startswith("ROS_")}
            out.update(ROS_MASTER_URI=f"http://{net.ip['hosta']}:11311/", ROS_IP=net.ip[host], PYTHONUNBUFFERED="1",
                       ROS_HOME=f"/tmp/nj_soak_cut_{os.getpid()}_{host}")  # fmt: skip
            return out

        master = net.run("hosta", [str(venv_bin / "roscore"), "-p", "11311"], env("hosta"), "roscore")
        if (
            master.wait_line(lambda line: "started core service" in line or "master" in line.lower(), 30)
            is None
        ):
            raise SoakFailure(f"the namespaced master did not start: {master.text()[-500:]}")
        net.run("hostb", [*node, "talker", "/soak_cut", "b"], env("hostb"), "talker")
        listener = net.run("hostc", [*node, "listener", "/soak_cut", "c"], env("hostc"), "listener")
        if listener.wait_line(lambda line: line.startswith("got b "), timeout=30) is None:
            raise SoakFailure(f"no stream across the namespaces: {listener.text()[-500:]}")
        for _ in range(rounds):
            net.cut("hostb")
            time.sleep(cut_s)
            mark = len(listener.lines)
            net.restore("hostb")
            restored = time.time()
            line = listener.wait_line(lambda text: text.startswith("got b "), timeout=30, start=mark)
            if line is None:
                raise SoakFailure(
                    f"the stream did not resume within 30 s of the link's restore: {listener.text()[-300:]}"
                )
            healed.append(float(line.split()[3]) - restored)
            time.sleep(1.0)
    finally:
        net.close()
    return healed


def leaks(start: dict[str, dict[str, float]], end: dict[str, dict[str, float]]) -> list[str]:
    """Each survivor's growth beyond :data:`TOLERANCE`, in words."""
    out = []
    for name, first in start.items():
        last = end[name]
        if name.startswith("master ") and "master 1" in start:
            # a restarted master re-learns the graph as nodes call it (each node's main client reconnects
            # on its next call): its bound is the first master's steady state for the same graph
            first = {k: max(v, start["master 1"][k]) for k, v in first.items()}
        for key, slack in TOLERANCE.items():
            slack += MASTER_POOL if key == "threads" and name.startswith("master") else 0
            if last[key] > first[key] + slack:
                out.append(f"{name}: {key} {first[key]:.0f} -> {last[key]:.0f} (allowed +{slack})")
        if last["rss"] > first["rss"] * RSS_FACTOR + RSS_SLACK_MB:
            out.append(f"{name}: RSS {first['rss']:.1f} -> {last['rss']:.1f} MB")
    return out


def failures(report: dict[str, Any]) -> list[str]:
    """Everything in a report that breaks the soak's acceptance."""
    out = list(report["leaks"])
    bag = report["bag"]
    if bag["in_bag"] != bag["acknowledged"]:
        out.append(f"bag holds {bag['in_bag']} messages, the recorder acknowledged {bag['acknowledged']}")
    out += [f"bag hole: {h}" for h in bag["holes"]]
    killed = report["killed_bag"]
    if killed["in_bag"] < killed["acknowledged"]:
        out.append(
            f"reindexed bag holds {killed['in_bag']}, the recorder acknowledged {killed['acknowledged']}"
        )
    out += [f"killed bag hole: {h}" for h in killed["holes"]]
    if report["master_restarts"] != 2:
        out.append(f"{report['master_restarts']} master restarts, not 2")
    return out


def format_report(report: dict[str, Any]) -> str:
    lines = [f"soak: {report['nodes']} nodes, {report['duration']:g} s of faults, {report['kills']} SIGKILLs, "
             f"{report['master_restarts']} master restarts (load {os.getloadavg()[0]:.2f})"]  # fmt: skip
    for kind, s in report["heal"].items():
        if s:
            lines.append(
                f"  heal after {kind:26s} n={s['n']:3d}  p50 {s['p50']:.2f} s  p95 {s['p95']:.2f} s  max {s['max']:.2f} s"
            )
    if report.get("cut_link_skipped"):
        lines.append(f"  heal after a cut link: not measured ({report['cut_link_skipped']})")
    for name, first in report["resources"]["start"].items():
        last = report["resources"]["end"][name]
        lines.append(f"  {name:14s} RSS {first['rss']:6.1f} -> {last['rss']:6.1f} MB  fds {first['fds']:.0f} -> "
                     f"{last['fds']:.0f}  threads {first['threads']:.0f} -> {last['threads']:.0f}")  # fmt: skip
    series = report["resources"]["rss_series"]
    if series:
        lines.append("  RSS trend (MB) of " + ", ".join(n for n in series[0] if n != "t") + ":")
        lines += [
            f"    t={row['t']:6.1f} s  " + "  ".join(f"{v:5.1f}" for n, v in row.items() if n != "t")
            for row in series
        ]
    b, k = report["bag"], report["killed_bag"]
    lines.append(f"  bag: {b['in_bag']} messages, recorder acknowledged {b['acknowledged']}, "
                 f"{b['incarnations']} publisher incarnations, holes {len(b['holes'])}")  # fmt: skip
    lines.append(
        f"  SIGKILLed recorder, reindexed: {k['in_bag']} messages >= acknowledged {k['acknowledged']}"
    )
    lines.append(f"  service calls ok {report['service_calls_ok']}, failed {report['service_calls_failed']} (failures: "
                 "calls to a killed provider)")  # fmt: skip
    return "\n".join(lines)


def main() -> int:
    parser = argparse.ArgumentParser(description="ninjemys soak test: 50 nodes, faults, a bag throughout")
    parser.add_argument("--duration", type=float, default=600.0, help="seconds of faults (default 600)")
    parser.add_argument("--nodes", type=int, default=50)
    parser.add_argument("--rate", type=float, default=10.0, help="publish rate per topic, Hz")
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--port", type=int, default=None, help="master port (default: a free one)")
    parser.add_argument("--json", help="also write the report here")
    parser.add_argument(
        "--trace-memory",
        action="store_true",
        help="diagnosis: print where worker w0's Python allocations grew (tracemalloc)",
    )
    parser.add_argument("--cut-rounds", type=int, default=20, help="cut-link rounds in namespaces (0: none)")
    opts = parser.parse_args()
    if opts.trace_memory:
        os.environ["SOAK_TRACE_MEMORY"] = "1"
    report = run_soak(
        duration=opts.duration, nodes=opts.nodes, rate=opts.rate, seed=opts.seed, port=opts.port
    )
    if opts.cut_rounds:
        cut = cut_link_heals(opts.cut_rounds)
        if isinstance(cut, str):
            report["heal"]["cut_link"] = {}
            report["cut_link_skipped"] = cut
        else:
            report["heal"]["cut_link"] = summarize(cut)
            report["heal_raw"]["cut_link"] = cut
    print(format_report(report))
    if opts.json:
        Path(opts.json).write_text(json.dumps(report, indent=1))
    bad = failures(report)
    for line in bad:
        print(f"FAIL: {line}")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())

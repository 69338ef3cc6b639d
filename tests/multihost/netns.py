"""Three hosts on one machine: Linux network namespaces joined by veth pairs to a bridge.

Each host has its own network stack, address (10.77.0.1-3), host name (``unshare --uts``) and
``/etc/hosts`` (``ip netns exec`` mounts ``/etc/netns/<ns>/hosts`` over it), so ROS_IP,
ROS_HOSTNAME and plain host names behave as on separate machines. The links can be cut and
restored, and shaped with ``tc netem``. Needs root and iproute2 (``make test`` installs it); the
tests skip with the reason where namespaces cannot be made (a CI sandbox without CAP_NET_ADMIN).
"""

from __future__ import annotations

import os
import shutil
import subprocess
import threading
import time
from collections.abc import Callable
from pathlib import Path

SUBNET = "10.77.0"


def _ip(*args: str, check: bool = True) -> subprocess.CompletedProcess:
    return subprocess.run(["ip", *args], capture_output=True, text=True, check=check, timeout=20)


def unavailable() -> str | None:
    """Why namespaces cannot be used here, or None."""
    if os.geteuid() != 0:
        return "network namespaces need root"
    for tool in ("ip", "unshare", "tc"):
        if shutil.which(tool) is None:
            return f"{tool} is not installed (make test installs iproute2 and util-linux)"
    probe = f"njprobe{os.getpid() % 100000}"
    made = _ip("netns", "add", probe, check=False)
    if made.returncode != 0:
        return f"cannot create a network namespace: {made.stderr.strip()}"
    _ip("netns", "del", probe, check=False)
    return None


class Proc:
    """A process on one host, its output lines collected as they come."""

    def __init__(self, popen: subprocess.Popen, name: str) -> None:
        self.popen, self.name = popen, name
        self.lines: list[str] = []
        self._cond = threading.Condition()
        threading.Thread(target=self._pump, daemon=True).start()

    def _pump(self) -> None:
        assert self.popen.stdout is not None
        for line in self.popen.stdout:
            with self._cond:
                self.lines.append(line.rstrip("\n"))
                self._cond.notify_all()

    def wait_line(self, pred: Callable[[str], bool], timeout: float = 20.0, start: int = 0) -> str | None:
        """The first line from index ``start`` on that ``pred`` accepts, waiting up to ``timeout``."""
        deadline = time.monotonic() + timeout
        with self._cond:
            seen = start
            while True:
                for line in self.lines[seen:]:
                    if pred(line):
                        return line
                seen = len(self.lines)
                left = deadline - time.monotonic()
                if left <= 0:
                    return None
                self._cond.wait(left)

    def text(self) -> str:
        with self._cond:
            return "\n".join(self.lines)

    def stop(self) -> None:
        if self.popen.poll() is None:
            self.popen.terminate()
            try:
                self.popen.wait(5)
            except subprocess.TimeoutExpired:
                self.popen.kill()
                self.popen.wait()


class Network:
    """Hosts ``hosta``, ``hostb``, ``hostc`` (10.77.0.1-3) on a bridge; :meth:`close` removes it all."""

    def __init__(self, hosts: tuple[str, ...] = ("hosta", "hostb", "hostc")) -> None:
        tag = f"nj{os.getpid() % 100000}"
        self.hosts = hosts
        self.bridge = f"{tag}br"
        self.ns = {h: f"{tag}{h}" for h in hosts}
        self.ip = {h: f"{SUBNET}.{i + 1}" for i, h in enumerate(hosts)}
        self.host_link = {h: f"v{tag}{i}" for i, h in enumerate(hosts)}  # inside the host
        self.bridge_link = {h: f"b{tag}{i}" for i, h in enumerate(hosts)}  # its peer on the bridge
        self.procs: list[Proc] = []
        self._made: list[str] = []
        try:
            self._build()
        except BaseException:
            self.close()
            raise

    def _build(self) -> None:
        _ip("netns", "add", self.bridge)
        self._made.append(self.bridge)
        _ip("-n", self.bridge, "link", "add", "br0", "type", "bridge")
        _ip("-n", self.bridge, "link", "set", "br0", "up")
        hosts_file = "127.0.0.1 localhost\n" + "".join(f"{self.ip[h]} {h}\n" for h in self.hosts)
        for h in self.hosts:
            ns = self.ns[h]
            _ip("netns", "add", ns)
            self._made.append(ns)
            etc = Path("/etc/netns") / ns
            etc.mkdir(parents=True, exist_ok=True)
            (etc / "hosts").write_text(hosts_file)
            _ip("link", "add", self.host_link[h], "type", "veth", "peer", "name", self.bridge_link[h])
            _ip("link", "set", self.host_link[h], "netns", ns)
            _ip("link", "set", self.bridge_link[h], "netns", self.bridge)
            _ip("-n", ns, "addr", "add", f"{self.ip[h]}/24", "dev", self.host_link[h])
            _ip("-n", ns, "link", "set", self.host_link[h], "up")
            _ip("-n", ns, "link", "set", "lo", "up")
            _ip("-n", self.bridge, "link", "set", self.bridge_link[h], "master", "br0")
            _ip("-n", self.bridge, "link", "set", self.bridge_link[h], "up")

    def argv(self, host: str, argv: list[str]) -> list[str]:
        """``argv`` run on ``host``: its network namespace and its own host name."""
        return ["ip", "netns", "exec", self.ns[host], "unshare", "--uts", "sh", "-c",
                'hostname "$0" && exec "$@"', host, *argv]  # fmt: skip

    def run(self, host: str, argv: list[str], env: dict[str, str], name: str = "") -> Proc:
        popen = subprocess.Popen(
            self.argv(host, argv),
            env=env,
            stdout=subprocess.PIPE,
            stderr=subprocess.STDOUT,
            stdin=subprocess.DEVNULL,
            text=True,
        )
        proc = Proc(popen, name or argv[-1])
        self.procs.append(proc)
        return proc

    def cut(self, host: str) -> None:
        _ip("-n", self.bridge, "link", "set", self.bridge_link[host], "down")

    def restore(self, host: str) -> None:
        _ip("-n", self.bridge, "link", "set", self.bridge_link[host], "up")

    def netem(self, host: str, *spec: str) -> str | None:
        """Shape what ``host`` sends (``"delay", "100ms", "loss", "10%"``); why it cannot, or None
        (a kernel built without the netem qdisc, as in some sandboxes, answers "unknown")."""
        done = subprocess.run(["ip", "netns", "exec", self.ns[host], "tc", "qdisc", "replace", "dev",
                               self.host_link[host], "root", "netem", *spec], capture_output=True, text=True)  # fmt: skip
        return None if done.returncode == 0 else f"tc netem: {done.stderr.strip()}"

    def clear_netem(self, host: str) -> None:
        subprocess.run(["ip", "netns", "exec", self.ns[host], "tc", "qdisc", "del", "dev", self.host_link[host],
                        "root"], capture_output=True)  # fmt: skip

    def close(self) -> None:
        for proc in self.procs:
            proc.stop()
        for ns in self._made:
            # anything still running in the namespace goes with it
            pids = subprocess.run(["ip", "netns", "pids", ns], capture_output=True, text=True).stdout.split()
            for pid in pids:
                try:
                    os.kill(int(pid), 9)
                except (ProcessLookupError, ValueError):
                    pass
            _ip("netns", "del", ns, check=False)
            shutil.rmtree(Path("/etc/netns") / ns, ignore_errors=True)

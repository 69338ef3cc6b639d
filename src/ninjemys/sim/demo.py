"""The turtlesim demo: roscore, turtlesim_node and square_driver, with the view and graph URLs.

``python -m ninjemys.sim.demo [--port 11311] [--web-port 8080]`` runs until Ctrl-C and then stops
every process it started. An already running master at the port is reused.
"""

from __future__ import annotations

import argparse
import os
import signal
import subprocess
import sys
import time
import xmlrpc.client

from ninjemys.testing import ninjemys_bin
from ninjemys.tools.cli import entry


def _master_up(uri: str) -> bool:
    try:
        xmlrpc.client.ServerProxy(uri).getPid("/demo")
        return True
    except OSError:
        return False


def _wait(predicate, timeout: float, what: str) -> None:  # type: ignore[no-untyped-def]
    deadline = time.monotonic() + timeout
    while not predicate():
        if time.monotonic() > deadline:
            raise TimeoutError(f"{what} did not come up within {timeout:.0f} s")
        time.sleep(0.05)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m ninjemys.sim.demo", description=__doc__.split("\n")[0])
    parser.add_argument("--port", type=int, default=11311, help="master port (default 11311)")
    parser.add_argument("--web-port", type=int, default=0, help="web view port (default: any free port)")
    options = parser.parse_args(argv)
    uri = f"http://localhost:{options.port}/"
    env = dict(os.environ, ROS_MASTER_URI=uri, PYTHONUNBUFFERED="1")
    env.setdefault("ROS_HOSTNAME", "localhost")
    procs: list[subprocess.Popen] = []
    try:
        if not _master_up(uri):
            procs.append(subprocess.Popen([ninjemys_bin("roscore"), "-p", str(options.port)], env=env))
            _wait(lambda: _master_up(uri), 20, "roscore")
        sim = subprocess.Popen(
            [ninjemys_bin("turtlesim_node"), "--port", str(options.web_port)],
            env=env,
            stdout=subprocess.PIPE,
            text=True,
        )
        procs.append(sim)
        assert sim.stdout is not None
        for line in sim.stdout:
            sys.stdout.write(line)
            if line.startswith("turtlesim view:"):
                break
        else:
            print("ERROR: turtlesim_node exited before serving its view", file=sys.stderr)
            return 1
        procs.append(subprocess.Popen([sys.executable, "-m", "ninjemys.sim.square_driver"], env=env))
        print("Driving turtle1 around a 1 m square. Open the URLs above; Ctrl-C stops the demo.", flush=True)
        for line in sim.stdout:  # keep relaying turtlesim's log until it ends or Ctrl-C
            sys.stdout.write(line)
        return 0
    except KeyboardInterrupt:
        return 0
    finally:
        for proc in reversed(procs):
            if proc.poll() is None:
                proc.send_signal(signal.SIGINT)
        for proc in reversed(procs):
            try:
                proc.wait(5)
            except subprocess.TimeoutExpired:
                proc.kill()
                proc.wait()


console_main = entry(main)

if __name__ == "__main__":
    console_main()

"""A Python node (ours or real rospy) run as a child process, its output collected line by line."""

from __future__ import annotations

import re
import signal
import subprocess
import threading
import time
from pathlib import Path


class NodeProc:
    """A Python node running as a child process, with its stdout/stderr collected line by line."""

    def __init__(self, cmd: list[str], env: dict[str, str], cwd: Path) -> None:
        self.cmd = cmd
        self.proc = subprocess.Popen(
            cmd, env=env, cwd=cwd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, stdin=subprocess.DEVNULL
        )
        self.out: list[str] = []
        self.err: list[str] = []
        self._cond = threading.Condition()
        self._readers = [
            threading.Thread(target=self._read, args=(self.proc.stdout, self.out), daemon=True),
            threading.Thread(target=self._read, args=(self.proc.stderr, self.err), daemon=True),
        ]
        for r in self._readers:
            r.start()

    def _read(self, stream, sink: list[str]) -> None:
        for raw in iter(stream.readline, b""):
            with self._cond:
                sink.append(raw.decode("utf-8", "replace").rstrip("\n"))
                self._cond.notify_all()
        stream.close()
        with self._cond:
            self._cond.notify_all()

    def wait_for(self, pattern: str, timeout: float = 15.0, stream: str = "out") -> re.Match[str]:
        """The first line of stdout (or stderr) matching ``pattern``; fails the test after ``timeout``."""
        regex = re.compile(pattern)
        sink = self.out if stream == "out" else self.err
        deadline = time.monotonic() + timeout
        with self._cond:
            while True:
                for line in sink:
                    m = regex.search(line)
                    if m:
                        return m
                left = deadline - time.monotonic()
                if left <= 0 or (
                    self.proc.poll() is not None and not any(r.is_alive() for r in self._readers)
                ):
                    raise AssertionError(
                        f"{self.cmd}: no line matching {pattern!r} on std{stream} within {timeout} s\n"
                        f"stdout: {self.out[-20:]}\nstderr: {self.err[-20:]}"
                    )
                self._cond.wait(min(left, 0.5))

    def interrupt(self) -> None:
        self.proc.send_signal(signal.SIGINT)

    def wait(self, timeout: float = 10.0) -> int:
        code = self.proc.wait(timeout)
        for r in self._readers:
            r.join(2.0)
        return code

    def kill(self) -> None:
        if self.proc.poll() is None:
            self.proc.kill()
        self.proc.wait()
        for r in self._readers:
            r.join(2.0)

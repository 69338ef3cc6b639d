"""Client side of the genpy oracle (genpy_oracle_server.py under Debian's /usr/bin/python3).

One long-lived subprocess per test session; each request is one JSON line out and one JSON line back.
"""

from __future__ import annotations

import json
import subprocess
from pathlib import Path
from typing import Any

from ninjemys.testing import ROS1_PYTHON, ros1_env

SERVER = Path(__file__).with_name("genpy_oracle_server.py")


class OracleError(AssertionError):
    """The oracle could not answer (the request named something genpy does not know, or genpy raised)."""


class GenpyOracle:
    def __init__(self) -> None:
        env = ros1_env("http://localhost:11311")
        self._proc = subprocess.Popen(
            [ROS1_PYTHON, "-u", str(SERVER)],
            stdin=subprocess.PIPE,
            stdout=subprocess.PIPE,
            env=env,
            text=True,
            bufsize=1,
        )
        self._defined: set[str] = set()

    def call(self, op: str, **params: Any) -> Any:
        assert self._proc.stdin is not None and self._proc.stdout is not None
        self._proc.stdin.write(json.dumps({"op": op, **params}) + "\n")
        self._proc.stdin.flush()
        line = self._proc.stdout.readline()
        if not line:
            raise OracleError(f"genpy oracle exited (code {self._proc.poll()}) while answering {op}")
        answer = json.loads(line)
        if "error" in answer:
            raise OracleError(f"genpy oracle failed on {op}: {answer['error']}")
        return answer["ok"]

    def define(self, type_name: str, full_text: str) -> str:
        """Make sure the oracle can build ``type_name``; returns 'debian' or 'dynamic'."""
        source = self.call("define", type=type_name, full_text=full_text)
        self._defined.add(type_name)
        return source

    def serialize(self, type_name: str, trees: list[dict]) -> list[bytes]:
        import base64

        return [base64.b64decode(b) for b in self.call("serialize", type=type_name, values=trees)]

    def deserialize(self, type_name: str, blobs: list[bytes]) -> list[dict]:
        import base64

        return self.call("deserialize", type=type_name, data=[base64.b64encode(b).decode() for b in blobs])

    def close(self) -> None:
        if self._proc.stdin is not None:
            self._proc.stdin.close()
        try:
            self._proc.wait(timeout=5)
        except subprocess.TimeoutExpired:
            self._proc.kill()
            self._proc.wait()
        if self._proc.stdout is not None:
            self._proc.stdout.close()

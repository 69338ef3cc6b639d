"""rosout aggregation: the rosout.log format and its rotation (the node itself is ninjemys.tools.rosout).

The log line is rosout.cpp's::

    <stamp.sec>.<stamp.nsec:09> <LEVEL> <node> [<file>:<line>(<function>)] [topics: <t1>, <t2>] <msg>

(the ``[topics: ...]`` part is omitted when ``/rosout/omit_topics`` is true), after a
``\\n\\n<now>  Node Startup\\n`` banner. The file rotates at 100 MB into ``rosout.log.1`` ...
``rosout.log.10``, as in ROS 1. ``ROSOUT_DISABLE_FILE_LOGGING`` turns the file off.
"""

from __future__ import annotations

import os
import threading
import time
from pathlib import Path
from typing import IO, Any

LEVELS = {1: "DEBUG", 2: "INFO", 4: "WARN", 8: "ERROR", 16: "FATAL"}
MAX_FILE_BYTES = 100 * 1024 * 1024
MAX_BACKUPS = 10


def _stamp(sec: int, nsec: int) -> str:
    return f"{sec}.{nsec:09d}"


def format_line(msg: Any, omit_topics: bool = False) -> str:
    """One rosout.log line for a ``rosgraph_msgs/Log`` message (ends with a newline)."""
    stamp = msg.header.stamp
    level = LEVELS.get(msg.level, str(msg.level))
    topics = "" if omit_topics else f"[topics: {', '.join(msg.topics)}] "
    return f"{_stamp(stamp.secs, stamp.nsecs)} {level} {msg.name} [{msg.file}:{msg.line}({msg.function})] {topics}{msg.msg}\n"


def file_logging_disabled(env: dict[str, str] | os._Environ[str] | None = None) -> bool:
    value = (os.environ if env is None else env).get("ROSOUT_DISABLE_FILE_LOGGING", "").strip().lower()
    return value not in ("", "0", "false", "off", "no")


class RosoutLog:
    """rosout.log with ROS 1's size-based rotation. Thread-safe."""

    def __init__(self, path: Path, max_bytes: int = MAX_FILE_BYTES, backups: int = MAX_BACKUPS) -> None:
        self.path = path
        self.max_bytes = max_bytes
        self.backups = backups
        self._backup_index = 0
        self._lock = threading.Lock()
        self._file: IO[str] = open(path, "w", encoding="utf-8", errors="replace")  # noqa: SIM115
        now = time.time()
        self._size = 0
        self._write(f"\n\n{_stamp(int(now), int((now % 1) * 1e9))}  Node Startup\n")

    def write(self, line: str) -> None:
        with self._lock:
            if self._file.closed:
                return
            self._write(line)
            if self._size > self.max_bytes:
                self._rotate()

    def _write(self, text: str) -> None:
        self._file.write(text)
        self._file.flush()
        self._size += len(text.encode("utf-8", "replace"))

    def _rotate(self) -> None:
        self._file.close()
        base = str(self.path)
        if self._backup_index == self.backups:
            Path(f"{base}.{self.backups}").unlink(missing_ok=True)
        for i in range(min(self.backups, self._backup_index + 1), 0, -1):
            source = Path(base if i == 1 else f"{base}.{i - 1}")
            if source.exists():
                source.replace(f"{base}.{i}")
        self._backup_index = min(self.backups, self._backup_index + 1)
        self._file = open(self.path, "w", encoding="utf-8", errors="replace")  # noqa: SIM115
        self._size = 0

    def close(self) -> None:
        with self._lock:
            self._file.close()

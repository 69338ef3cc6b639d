"""The rosout node: subscribes /rosout, republishes every message on /rosout_agg, writes rosout.log.

It is an ordinary node of the ninjemys runtime (``ninjemys.node.Node``), started by ``roscore`` inside
its own process once the master answers: one interpreter instead of two makes ``roscore`` ready
sooner and lets Ctrl-C stop everything at once. Messages are relayed without re-serializing
(``raw=True`` in, ``publish_raw`` out); each is decoded once, for its log line.

The log line is rosout.cpp's::

    <stamp.sec>.<stamp.nsec:09> <LEVEL> <node> [<file>:<line>(<function>)] [topics: <t1>, <t2>] <msg>

(the ``[topics: ...]`` part is omitted when ``/rosout/omit_topics`` is true), after a
``\\n\\n<now>  Node Startup\\n`` banner. The file rotates at 100 MB into ``rosout.log.1`` ...
``rosout.log.10``, as in ROS 1. ``ROSOUT_DISABLE_FILE_LOGGING`` turns the file off.
"""

from __future__ import annotations

import logging
import os
import threading
import time
from pathlib import Path
from typing import IO, Any

log = logging.getLogger(__name__)

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


class Rosout:
    """The running rosout node (``stop()`` shuts it down)."""

    def __init__(self, master_uri: str, log_dir: Path | None, node_name: str = "/rosout") -> None:
        from ninjemys.idl.loader import get_message_class
        from ninjemys.node import Node

        self.log_class = get_message_class("rosgraph_msgs/Log")
        self.file: RosoutLog | None = None
        if log_dir is not None and not file_logging_disabled():
            self.file = RosoutLog(log_dir / "rosout.log")
        self.node = Node(node_name, master_uri=master_uri)
        try:
            self.omit_topics = bool(self.node.get_param("/rosout/omit_topics", False))
            self.agg = self.node.publisher("/rosout_agg", self.log_class, queue_size=None)
            self.sub = self.node.subscriber(
                "/rosout", self.log_class, self._on_message, queue_size=None, raw=True
            )
        except BaseException:
            self.stop()
            raise

    def _on_message(self, raw: Any) -> None:
        self.agg.publish_raw(raw.data)
        if self.file is None:
            return
        try:
            msg = self.log_class.deserialize_from(bytes(raw.data))
        except Exception as exc:  # a broken publisher must not stop the log
            log.warning("rosout: undecodable message from %s: %s", raw.connection_header.get("callerid"), exc)
            return
        self.file.write(format_line(msg, self.omit_topics))

    def stop(self) -> None:
        try:
            self.node.shutdown("roscore shutting down")
        finally:
            if self.file is not None:
                self.file.close()


def main(argv: list[str] | None = None) -> int:
    """``rosrun rosout rosout``: rosout as a process of its own (``roscore`` runs it in-process).

    Honours the usual node arguments (``__name:=``, ``__master:=``, ...); rosout.log goes to
    ``<log dir>/<run_id>/`` like roscore's.
    """
    import sys

    from ninjemys.errors import MasterError
    from ninjemys.master.client import MasterClient
    from ninjemys.node.cli_args import parse_args
    from ninjemys.roshome import log_directory

    args = parse_args(["rosout", *(sys.argv[1:] if argv is None else argv)])
    name = args.full_name(args.node_name("rosout"))
    log_dir = log_directory()
    try:
        log_dir = log_dir / str(MasterClient(args.master_uri, name, timeout=5.0).get_param("/run_id"))
    except MasterError:
        pass  # no /run_id (a bare master): log straight into the log directory
    log_dir.mkdir(parents=True, exist_ok=True)
    rosout = Rosout(args.master_uri, log_dir, node_name=name)
    try:
        rosout.node.wait_for_shutdown()
    except KeyboardInterrupt:
        pass
    finally:
        rosout.stop()
    return 0

"""User-facing node logging with ROS 1's routing: console, the node's log file, and /rosout.

``rospy.loginfo("hello")`` must look and land exactly as under ROS 1 (the table of the rospy logging
overview)::

              Debug  Info  Warn  Error  Fatal
    stdout     (X)    X
    stderr                  X     X      X
    log file    X     X     X     X      X
    /rosout     (X)   X     X     X      X      (debug only when the level is DEBUG)

Console lines are rospy's ``[INFO] [1676758538.565952]: msg`` (``ROSCONSOLE_FORMAT`` honoured, with
``, <sim time>`` appended under simulated time); the log file is ``<node>-<pid>.log`` in ROS_LOG_DIR,
else ROS_HOME/log, else ~/.ros/log (``__log:=`` names the file), written lazily so a node that never
logs never touches the disk. /rosout carries latched ``rosgraph_msgs/Log`` messages naming the node's
publications in ``topics``.

The logger is a plain object owned by a node, not Python's logging tree: one formatted write per
message, no handler chain, and nothing imported until a message is actually written. The
``~get_loggers``/``~set_logger_level`` services (roscpp/GetLoggers, roscpp/SetLoggerLevel) are served
from :meth:`NodeLog.get_loggers` and :meth:`NodeLog.set_logger_level`.
"""

from __future__ import annotations

import os
import sys
import threading
import time
from collections.abc import Callable

from ninjemys.errors import ParameterError

TYPE_CHECKING = False  # importing typing costs ~7 ms of every node's start-up; checkers set it

if TYPE_CHECKING:
    from pathlib import Path
    from typing import IO, Any

# rosgraph_msgs/Log level constants (also rospy.DEBUG ... rospy.FATAL)
DEBUG = 1
INFO = 2
WARN = 4
ERROR = 8
FATAL = 16

LEVEL_NAMES = {DEBUG: "DEBUG", INFO: "INFO", WARN: "WARN", ERROR: "ERROR", FATAL: "FATAL"}
_NAME_TO_LEVEL = {"DEBUG": DEBUG, "INFO": INFO, "WARN": WARN, "WARNING": WARN, "ERROR": ERROR, "FATAL": FATAL}
_FILE_LEVEL_NAMES = {DEBUG: "DEBUG", INFO: "INFO", WARN: "WARNING", ERROR: "ERROR", FATAL: "CRITICAL"}
_COLORS = {DEBUG: "\033[32m", WARN: "\033[33m", ERROR: "\033[31m", FATAL: "\033[31m"}
_COLOR_RESET = "\033[0m"
_DEFAULT_FORMAT = "[${severity}] [${time}]: ${message}"

#: the logger name ROS 1 tools (rqt_logger_level, rosnode) show for a node's own messages
USER_LOGGER = "rosout"


def level_from_name(name: str) -> int:
    """``"warn"`` -> WARN; raises ParameterError naming the accepted levels."""
    try:
        return _NAME_TO_LEVEL[name.strip().upper()]
    except KeyError:
        raise ParameterError(
            f"unknown logger level [{name}]: expected debug, info, warn, error or fatal"
        ) from None


def log_file_path(node_name: str, log_file: str | None = None, pid: int | None = None) -> Path:
    """``/ns/talker_1_2`` -> ``<log dir>/ns_talker_1_2-<pid>.log``; ``__log:=`` (``log_file``) wins."""
    # imported here: pathlib is needed only once a message is written to the file, not at start-up
    from pathlib import Path

    from ninjemys.roshome import log_directory

    if log_file:
        return Path(log_file).expanduser()
    stem = node_name.replace("/", "_").lstrip("_") or "node"
    return log_directory() / f"{stem}-{os.getpid() if pid is None else pid}.log"


def format_console(
    level: int, message: str, wall: float, sim: float | None = None, fmt: str | None = None
) -> str:
    """One console line exactly as rospy prints it (without the newline)."""
    fmt = os.environ.get("ROSCONSOLE_FORMAT", _DEFAULT_FORMAT) if fmt is None else fmt
    stamp = "%f" % wall if sim is None else "%f, %f" % (wall, sim)
    if fmt == _DEFAULT_FORMAT:
        return f"[{LEVEL_NAMES[level]}] [{stamp}]: {message}"
    line = fmt.replace("${severity}", LEVEL_NAMES[level]).replace("${message}", message)
    return line.replace("${time}", stamp).replace("${walltime}", "%f" % wall)


_stamp_cache: tuple[int, str] = (-1, "")


def format_file(level: int, message: str, wall: float) -> str:
    """One log-file line in rospy's layout: ``[rosout][INFO] 2023-02-18 12:34:56,789: msg``."""
    global _stamp_cache
    second = int(wall)
    cached_second, stamp = _stamp_cache  # one tuple: readers never see a half-updated pair
    if cached_second != second:  # strftime once per second, not once per message
        stamp = time.strftime("%Y-%m-%d %H:%M:%S", time.localtime(second))
        _stamp_cache = (second, stamp)
    return f"[{USER_LOGGER}][{_FILE_LEVEL_NAMES[level]}] {stamp},{int(wall % 1 * 1000):03d}: {message}"


class _CallSiteFilter:
    """Per call-site state for the _throttle / _once / _throttle_identical variants."""

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._last_time: dict[tuple[str, int], float] = {}
        self._last_message: dict[tuple[str, int], str] = {}
        self._done: set[tuple[str, int]] = set()

    def throttle(self, site: tuple[str, int], period: float, now: float) -> bool:
        """True when ``period`` has passed since the last pass at ``site`` (or time went backwards)."""
        with self._lock:
            last = self._last_time.get(site)
            if last is None or now - last >= period or now < last:
                self._last_time[site] = now
                return True
            return False

    def identical(self, site: tuple[str, int], message: str) -> bool:
        """True when ``message`` differs from the last one logged at ``site``."""
        with self._lock:
            if self._last_message.get(site) == message:
                return False
            self._last_message[site] = message
            return True

    def once(self, site: tuple[str, int]) -> bool:
        with self._lock:
            if site in self._done:
                return False
            self._done.add(site)
            return True


class NodeLog:
    """The logging path of one node: console, log file and (once attached) /rosout.

    Args:
        node_name: the node's global name (names the log file and fills ``Log.name``).
        level: threshold for console and /rosout (the file records every message).
        log_file: ``__log:=`` override for the file path.
        ros_time: seconds of ROS time when it is simulated (shown next to wall time, stamps /rosout).
        write_file: False for console-only logging (rospy's messages before init_node).
    """

    def __init__(
        self,
        node_name: str,
        level: int = INFO,
        log_file: str | None = None,
        ros_time: Callable[[], float] | None = None,
        stdout: IO[str] | None = None,
        stderr: IO[str] | None = None,
        colorize: bool = True,
        write_file: bool = True,
    ) -> None:
        self.node_name = node_name
        self.level = level
        self._log_file = log_file
        self._path: Path | None = None
        self._ros_time = ros_time
        self._stdout = stdout
        self._stderr = stderr
        self._colorize = colorize
        self._file: IO[str] | None = None
        self._file_failed = not write_file
        self._lock = threading.Lock()
        self._filter = _CallSiteFilter()
        self._rosout: Any = None
        self._held: list[tuple[int, str, float, str, str, int]] | None = None
        self._held_limit = 100
        self._hold_lock = threading.Lock()
        self._log_class: Any = None
        self._time_class: Any = None
        self._topics: Callable[[], list[str]] = list
        self._closed = False

    @property
    def path(self) -> Path:
        """The log file (created with its directory on the first message written to it)."""
        if self._path is None:
            self._path = log_file_path(self.node_name, self._log_file)
        return self._path

    # -- wiring -----------------------------------------------------------------------------------------
    def attach_rosout(self, publisher: Any, log_class: type, topics: Callable[[], list[str]]) -> None:
        """Start sending every enabled message to /rosout through ``publisher`` (latched rosgraph_msgs/Log)."""
        from ninjemys.rostime import Time

        self._time_class = Time
        self._log_class = log_class
        self._topics = topics
        with self._hold_lock:
            held, self._held = self._held or [], None
            for record in held:
                self._send(publisher, record)
            self._rosout = publisher

    def hold_rosout(self, limit: int = 100) -> None:
        """Keep up to ``limit`` messages for /rosout until :meth:`attach_rosout` (set up in the background)."""
        self._held_limit = limit
        self._held = []

    def set_ros_time(self, ros_time: Callable[[], float] | None) -> None:
        """Show simulated time next to wall time (None: wall clock only)."""
        self._ros_time = ros_time

    # -- the logging calls ----------------------------------------------------------------------------------
    def log(self, level: int, msg: Any, *args: Any, depth: int = 1, exc_info: bool = False) -> None:
        """Log ``msg % args`` at ``level``; ``depth`` frames up is the call site recorded in /rosout."""
        if self._closed and level < WARN:
            return
        if len(args) == 1 and isinstance(args[0], dict) and args[0]:
            args = args[0]  # type: ignore[assignment]  # "%(a)s", {"a": 1}: the logging module's rule, as rospy
        text = str(msg) % args if args else str(msg)
        if exc_info:
            import traceback

            text = text + "\n" + traceback.format_exc().rstrip()
        wall = time.time()
        self._write_file(level, text, wall)
        if level < self.level:
            return
        sim = self._ros_time() if self._ros_time is not None else None
        self._write_console(level, format_console(level, text, wall, sim))  # debug too, once enabled (rospy)
        if self._rosout is not None or self._held is not None:
            code = sys._getframe(depth)
            record = (
                level,
                text,
                sim if sim is not None else wall,
                code.f_code.co_filename,
                code.f_code.co_name,
                code.f_lineno,
            )
            publisher = self._rosout
            if publisher is not None:
                self._send(publisher, record)
                return
            with self._hold_lock:
                if self._rosout is None and self._held is not None:
                    if len(self._held) < self._held_limit:
                        self._held.append(record)
                    return
            self._send(self._rosout, record)

    def log_throttle(self, period: float, level: int, msg: Any, *args: Any, depth: int = 1) -> None:
        """Log at most once per ``period`` seconds (of ROS time) from one call site."""
        frame = sys._getframe(depth)
        if self._filter.throttle((frame.f_code.co_filename, frame.f_lineno), period, self._now()):
            self.log(level, msg, *args, depth=depth + 1)

    def log_once(self, level: int, msg: Any, *args: Any, depth: int = 1) -> None:
        """Log only the first time this call site is reached."""
        frame = sys._getframe(depth)
        if self._filter.once((frame.f_code.co_filename, frame.f_lineno)):
            self.log(level, msg, *args, depth=depth + 1)

    def log_throttle_identical(
        self, period: float | None, level: int, msg: Any, *args: Any, depth: int = 1
    ) -> None:
        """Log when the message differs from this call site's last one, or ``period`` has passed."""
        frame = sys._getframe(depth)
        site = (frame.f_code.co_filename, frame.f_lineno)
        elapsed = period is not None and self._filter.throttle(site, period, self._now())
        changed = self._filter.identical(site, str(msg))
        if changed or elapsed:
            self.log(level, msg, *args, depth=depth + 1)

    def debug(self, msg: Any, *args: Any) -> None:
        self.log(DEBUG, msg, *args, depth=2)

    def info(self, msg: Any, *args: Any) -> None:
        self.log(INFO, msg, *args, depth=2)

    def warn(self, msg: Any, *args: Any) -> None:
        self.log(WARN, msg, *args, depth=2)

    def error(self, msg: Any, *args: Any) -> None:
        self.log(ERROR, msg, *args, depth=2)

    def fatal(self, msg: Any, *args: Any) -> None:
        self.log(FATAL, msg, *args, depth=2)

    # -- logger services (roscpp/GetLoggers, roscpp/SetLoggerLevel) ------------------------------------------
    def logger_levels(self) -> dict[str, str]:
        """Logger name -> lowercase level, as ``~get_loggers`` reports them."""
        import logging

        levels = {USER_LOGGER: LEVEL_NAMES[self.level].lower()}
        for name in ("ninjemys",):
            lvl = logging.getLogger(name).getEffectiveLevel()
            levels[name] = {10: "debug", 20: "info", 30: "warn", 40: "error", 50: "fatal"}.get(lvl, "info")
        return levels

    def set_logger_level(self, logger: str, level: str) -> None:
        """Change a logger's level (``rosout`` is the node's own messages); raises ParameterError."""
        value = level_from_name(level)
        if logger in (USER_LOGGER, "rospy", ""):
            self.level = value
            return
        import logging

        py_level = {DEBUG: 10, INFO: 20, WARN: 30, ERROR: 40, FATAL: 50}[value]
        logging.getLogger(logger).setLevel(py_level)

    def get_loggers_handler(self, response_class: type, logger_class: type) -> Callable[[Any], Any]:
        """A service handler for ``~get_loggers`` building roscpp/GetLoggers responses."""

        def handle(_request: Any) -> Any:
            items = [logger_class(name=n, level=lvl) for n, lvl in self.logger_levels().items()]
            return response_class(loggers=items)

        return handle

    def set_logger_level_handler(self, response_class: type) -> Callable[[Any], Any]:
        """A service handler for ``~set_logger_level`` (an unknown level is a service error)."""

        def handle(request: Any) -> Any:
            self.set_logger_level(request.logger, request.level)
            return response_class()

        return handle

    def detach(self) -> None:
        """The node is shutting down: stop sending to /rosout and close the log file. The program may
        still log afterwards (console, and the file, reopened on the next message)."""
        with self._hold_lock:
            self._rosout = None
            self._held = None
        with self._lock:
            if self._file is not None:
                self._file.close()
                self._file = None

    def close(self) -> None:
        """Flush and close the log file; later debug/info messages are dropped, warnings still print."""
        self._closed = True
        with self._lock:
            if self._file is not None:
                self._file.close()
                self._file = None
        self._rosout = None
        self._held = None

    # -- internals --------------------------------------------------------------------------------------
    def _now(self) -> float:
        return self._ros_time() if self._ros_time is not None else time.time()

    def _write_console(self, level: int, line: str) -> None:
        stream = (self._stdout or sys.stdout) if level <= INFO else (self._stderr or sys.stderr)
        color = _COLORS.get(level)
        if self._colorize and color and stream.isatty():
            line = color + line + _COLOR_RESET
        try:
            stream.write(line + "\n")
            stream.flush()
        except (OSError, ValueError):
            # a closed pipe (`talker.py | head`) must not kill the node
            pass

    def _write_file(self, level: int, text: str, wall: float) -> None:
        if self._file_failed or self._closed:
            return
        with self._lock:
            if self._file is None:
                try:
                    self.path.parent.mkdir(parents=True, exist_ok=True)
                    self._file = open(self.path, "a", buffering=1, encoding="utf-8")  # noqa: SIM115
                except OSError as exc:
                    self._file_failed = True
                    print(f"WARNING: cannot write the log file {self.path}: {exc}", file=sys.stderr)
                    return
            self._file.write(format_file(level, text, wall) + "\n")

    def _send(self, publisher: Any, record: tuple[int, str, float, str, str, int]) -> None:
        level, text, stamp, path, function, line = record
        try:
            msg = self._log_class(level=level, name=self.node_name, msg=text)
            msg.file = os.path.basename(path)
            msg.function = function
            msg.line = line
            msg.topics = list(self._topics())
            secs = int(stamp)
            msg.header.stamp = self._time_class(secs, int((stamp - secs) * 1e9))
            publisher.publish(msg)
        except Exception as exc:  # a broken /rosout must never take the node's logging down with it
            self._rosout = None
            self._write_console(ERROR, format_console(ERROR, f"/rosout disabled: {exc}", time.time()))

"""Node logging: rospy's console format, ROS 1's level routing, the log file and /rosout."""

from __future__ import annotations

import io
import re
from dataclasses import dataclass, field
from pathlib import Path

import pytest

from ninjemys.errors import ParameterError
from ninjemys.node import log as nlog
from ninjemys.node.log import DEBUG, ERROR, FATAL, INFO, WARN, NodeLog, format_console, log_file_path

LINE = re.compile(r"^\[(INFO|WARN|ERROR|FATAL|DEBUG)\] \[\d+\.\d{6}(?:, \d+\.\d{6})?\]: (.*)$")


@dataclass
class _Stamp:
    secs: int = 0
    nsecs: int = 0


@dataclass
class _Header:
    stamp: _Stamp = field(default_factory=_Stamp)


@dataclass
class FakeLog:
    level: int = 0
    name: str = ""
    msg: str = ""
    file: str = ""
    function: str = ""
    line: int = 0
    topics: list = field(default_factory=list)
    header: _Header = field(default_factory=_Header)


class FakePublisher:
    def __init__(self) -> None:
        self.sent: list[FakeLog] = []

    def publish(self, msg: FakeLog) -> None:
        self.sent.append(msg)


def make(tmp_path: Path, level: int = INFO) -> tuple[NodeLog, io.StringIO, io.StringIO, FakePublisher]:
    out, err = io.StringIO(), io.StringIO()
    logger = NodeLog("/talker", level=level, log_file=str(tmp_path / "node.log"), stdout=out, stderr=err)
    pub = FakePublisher()
    logger.attach_rosout(pub, FakeLog, lambda: ["/chatter", "/rosout"])
    return logger, out, err, pub


def test_console_format_is_rospys() -> None:
    assert format_console(INFO, "hello", 1676758538.5659521, fmt=None) == "[INFO] [1676758538.565952]: hello"
    assert format_console(WARN, "w", 1.0, sim=2.5) == "[WARN] [1.000000, 2.500000]: w"


def test_rosconsole_format_env(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("ROSCONSOLE_FORMAT", "${severity}:${message}")
    assert format_console(ERROR, "boom", 1.0) == "ERROR:boom"


def test_routing_follows_the_ros1_table(tmp_path: Path) -> None:
    logger, out, err, pub = make(tmp_path)
    logger.debug("d %d", 1)
    logger.info("i %s", "x")
    logger.warn("w")
    logger.error("e")
    logger.fatal("f")
    out_lines = out.getvalue().splitlines()
    err_lines = err.getvalue().splitlines()
    assert [LINE.match(x).groups() for x in out_lines] == [("INFO", "i x")]
    assert [LINE.match(x).groups() for x in err_lines] == [("WARN", "w"), ("ERROR", "e"), ("FATAL", "f")]
    # debug is disabled at INFO: not on /rosout, but in the log file
    assert [(m.level, m.msg) for m in pub.sent] == [(INFO, "i x"), (WARN, "w"), (ERROR, "e"), (FATAL, "f")]
    text = (tmp_path / "node.log").read_text()
    for piece in ("[rosout][DEBUG]", "d 1", "[rosout][INFO]", "[rosout][WARNING]", "[rosout][CRITICAL]"):
        assert piece in text


def test_debug_enabled_goes_to_stdout_and_rosout(tmp_path: Path) -> None:
    # Debian's rospy under init_node(log_level=rospy.DEBUG) prints "[DEBUG] [...]: dbg" on stdout
    logger, out, err, pub = make(tmp_path, level=DEBUG)
    logger.debug("dbg")
    assert [LINE.match(x).groups() for x in out.getvalue().splitlines()] == [("DEBUG", "dbg")]
    assert err.getvalue() == ""
    assert [(m.level, m.msg) for m in pub.sent] == [(DEBUG, "dbg")]


def test_rosout_message_fields(tmp_path: Path) -> None:
    logger, _, _, pub = make(tmp_path)
    logger.info("hi")
    (msg,) = pub.sent
    assert msg.name == "/talker"
    assert msg.topics == ["/chatter", "/rosout"]
    assert msg.file == "test_log.py"
    assert msg.function == "test_rosout_message_fields"
    assert msg.line > 0
    assert msg.header.stamp.secs > 1_600_000_000


def test_level_threshold_filters_console_and_rosout(tmp_path: Path) -> None:
    logger, out, err, pub = make(tmp_path, level=ERROR)
    logger.info("quiet")
    logger.warn("quiet too")
    logger.error("loud")
    assert out.getvalue() == ""
    assert "loud" in err.getvalue() and "quiet" not in err.getvalue()
    assert [m.msg for m in pub.sent] == ["loud"]


def test_throttle_once_identical(tmp_path: Path) -> None:
    now = [100.0]
    logger, out, _, _ = make(tmp_path)
    logger.set_ros_time(lambda: now[0])
    for _ in range(3):
        logger.log_throttle(1.0, INFO, "thr")
    now[0] += 1.5
    logger.log_throttle(1.0, INFO, "thr")
    for _ in range(3):
        logger.log_once(INFO, "once")
    for text in ("a", "a", "b", "b", "a"):
        logger.log_throttle_identical(None, INFO, text)
    messages = [LINE.match(x).group(2) for x in out.getvalue().splitlines()]
    assert messages == ["thr", "thr", "once", "a", "b", "a"]


def test_throttle_resets_when_time_moves_backwards(tmp_path: Path) -> None:
    now = [100.0]
    logger, out, _, _ = make(tmp_path)
    logger.set_ros_time(lambda: now[0])
    logger.log_throttle(10.0, INFO, "t")
    now[0] = 5.0
    logger.log_throttle(10.0, INFO, "t")
    assert len(out.getvalue().splitlines()) == 2


def test_logger_services(tmp_path: Path) -> None:
    logger, out, _, _ = make(tmp_path)
    assert logger.logger_levels()["rosout"] == "info"
    logger.set_logger_level("rosout", "warn")
    logger.info("hidden")
    assert out.getvalue() == ""
    assert logger.logger_levels()["rosout"] == "warn"
    with pytest.raises(ParameterError, match="unknown logger level"):
        logger.set_logger_level("rosout", "loud")

    @dataclass
    class Logger:
        name: str
        level: str

    @dataclass
    class Resp:
        loggers: list = field(default_factory=list)

    handler = logger.get_loggers_handler(Resp, Logger)
    assert Logger("rosout", "warn") in handler(None).loggers


def test_log_file_location(monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> None:
    monkeypatch.setenv("ROS_HOME", str(tmp_path / "home"))
    monkeypatch.delenv("ROS_LOG_DIR", raising=False)
    path = log_file_path("/ns/talker_1", pid=42)
    assert path == tmp_path / "home" / "log" / "ns_talker_1-42.log"
    monkeypatch.setenv("ROS_LOG_DIR", str(tmp_path / "logs"))
    assert log_file_path("/a", pid=1) == tmp_path / "logs" / "a-1.log"
    assert log_file_path("/a", log_file=str(tmp_path / "x.log")) == tmp_path / "x.log"
    # nothing is written until the first message
    logger = NodeLog("/lazy")
    assert not logger.path.exists()


def test_broken_rosout_does_not_break_logging(tmp_path: Path) -> None:
    logger, out, err, _ = make(tmp_path)

    class Broken:
        def publish(self, msg: object) -> None:
            raise OSError("gone")

    logger.attach_rosout(Broken(), FakeLog, list)
    logger.info("one")
    logger.info("two")
    assert out.getvalue().count("\n") == 2
    assert err.getvalue().count("/rosout disabled") == 1


def test_level_names() -> None:
    assert nlog.level_from_name("Warn") == WARN
    assert nlog.level_from_name("fatal") == FATAL


def test_messages_held_until_rosout_is_attached(tmp_path: Path) -> None:
    out = io.StringIO()
    logger = NodeLog("/early", log_file=str(tmp_path / "e.log"), stdout=out, stderr=io.StringIO())
    logger.hold_rosout(limit=2)
    logger.info("first")
    logger.warn("second")
    logger.error("third (over the limit)")
    pub = FakePublisher()
    logger.attach_rosout(pub, FakeLog, list)
    logger.info("after")
    assert [(m.level, m.msg) for m in pub.sent] == [(INFO, "first"), (WARN, "second"), (INFO, "after")]
    assert pub.sent[0].function == "test_messages_held_until_rosout_is_attached"
    assert "first" in out.getvalue()

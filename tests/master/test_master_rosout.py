"""rosout.log: ROS 1's line format, the startup banner, rotation, and the disable switch."""

from __future__ import annotations

from pathlib import Path
from types import SimpleNamespace

from ninjemys.master.rosout import RosoutLog, file_logging_disabled, format_line


def _msg(level: int = 2, topics: list[str] | None = None) -> SimpleNamespace:
    return SimpleNamespace(
        header=SimpleNamespace(stamp=SimpleNamespace(secs=1700000000, nsecs=5000)),
        level=level,
        name="/talker",
        msg="hello world 3",
        file="talker.py",
        function="talk",
        line=42,
        topics=topics if topics is not None else ["/chatter", "/rosout"],
    )


def test_line_format_matches_rosout_cpp() -> None:
    assert format_line(_msg()) == (
        "1700000000.000005000 INFO /talker [talker.py:42(talk)] [topics: /chatter, /rosout] hello world 3\n"
    )
    assert format_line(_msg(level=16, topics=[])).startswith(
        "1700000000.000005000 FATAL /talker [talker.py:42(talk)] [topics: ] "
    )
    assert " 3 /talker " in format_line(_msg(level=3))  # unknown levels print their number
    assert "[topics:" not in format_line(_msg(), omit_topics=True)


def test_banner_and_rotation(tmp_path: Path) -> None:
    log = RosoutLog(tmp_path / "rosout.log", max_bytes=200, backups=2)
    text = (tmp_path / "rosout.log").read_text()
    assert text.startswith("\n\n") and text.endswith("  Node Startup\n")
    for i in range(30):
        log.write(f"line {i:03d} " + "x" * 40 + "\n")
    log.close()
    assert (tmp_path / "rosout.log.1").exists() and (tmp_path / "rosout.log.2").exists()
    assert not (tmp_path / "rosout.log.3").exists()
    assert (
        "line 029" in (tmp_path / "rosout.log").read_text()
        or "line 029" in (tmp_path / "rosout.log.1").read_text()
    )


def test_disable_switch() -> None:
    assert not file_logging_disabled({})
    assert not file_logging_disabled({"ROSOUT_DISABLE_FILE_LOGGING": "false"})
    assert file_logging_disabled({"ROSOUT_DISABLE_FILE_LOGGING": "1"})
    assert file_logging_disabled({"ROSOUT_DISABLE_FILE_LOGGING": "True"})

"""The on-disk cache of compiled classes: reused, keyed by source, robust to junk, can be disabled."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from ninjemys.idl import codecache

SOURCE = "VALUE = 41 + 1\n"


def _run(code) -> dict:
    namespace: dict = {}
    exec(code, namespace)  # noqa: S102
    return namespace


def test_second_compile_comes_from_the_cache(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("ROS_HOME", str(tmp_path))
    first = codecache.compile_cached(SOURCE, "<t>")
    files = os.listdir(codecache.cache_dir())
    assert len(files) == 1 and files[0].endswith(".code")
    calls = []
    monkeypatch.setattr(codecache, "compile", lambda *a: calls.append(a), raising=False)
    second = codecache.compile_cached(SOURCE, "<t>")
    assert calls == [] and _run(second)["VALUE"] == 42 == _run(first)["VALUE"]
    codecache.compile_cached(SOURCE + "OTHER = 1\n", "<t>")
    assert len(os.listdir(codecache.cache_dir())) == 2  # a different source is a different entry


def test_corrupt_entries_are_recompiled(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("ROS_HOME", str(tmp_path))
    codecache.compile_cached(SOURCE, "<t>")
    folder = codecache.cache_dir()
    for name in os.listdir(folder):
        Path(folder, name).write_bytes(b"\x00garbage")
    assert _run(codecache.compile_cached(SOURCE, "<t>"))["VALUE"] == 42


def test_unwritable_or_disabled_cache_still_compiles(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    blocker = tmp_path / "file"
    blocker.write_text("not a directory")
    monkeypatch.setenv("ROS_HOME", str(blocker))
    assert _run(codecache.compile_cached(SOURCE, "<t>"))["VALUE"] == 42
    monkeypatch.setenv("NINJEMYS_CODE_CACHE", "0")
    assert codecache.cache_dir() is None
    assert _run(codecache.compile_cached(SOURCE, "<t>"))["VALUE"] == 42

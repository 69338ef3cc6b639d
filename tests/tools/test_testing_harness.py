"""``ninjemys.testing``'s polling wait and node-process harness, which every process test relies on."""

from __future__ import annotations

import os
import sys
import time

import pytest

from ninjemys.errors import NinjemysError
from ninjemys.testing import NodeProcess, WaitTimeout, wait_until


def test_wait_until_returns_the_first_truthy_value():
    calls = []

    def ready():
        calls.append(1)
        return len(calls) >= 3 and "value"

    assert wait_until(ready, timeout=5, step=0.001) == "value"
    assert len(calls) == 3


def test_wait_until_fails_the_test_naming_what_it_waited_for():
    with pytest.raises(WaitTimeout, match=r"timed out after 0.05 s waiting for the moon") as caught:
        wait_until(lambda: None, timeout=0.05, what="the moon", step=0.01)
    assert isinstance(caught.value, AssertionError) and isinstance(caught.value, NinjemysError)


def test_wait_until_asks_once_more_at_the_deadline():
    start = time.monotonic()
    assert wait_until(lambda: time.monotonic() - start > 0.05, timeout=0.05, step=1.0)


SCRIPT = """
import signal, subprocess, sys, time
if sys.argv[1] == "term":
    signal.signal(signal.SIGTERM, lambda *_: sys.exit(7))
print("hello 42", flush=True)
print("to stderr", file=sys.stderr, flush=True)
if sys.argv[1] == "exit":
    sys.exit(3)
if sys.argv[1] == "grandchild":
    print("pid", subprocess.Popen([sys.executable, "-c", "import time; time.sleep(60)"]).pid, flush=True)
time.sleep(60)
"""


def _start(mode: str, **kw) -> NodeProcess:
    return NodeProcess([sys.executable, "-c", SCRIPT, mode], **kw)


def test_lines_are_matched_by_regex_or_predicate_on_either_stream():
    with _start("sleep") as child:
        assert child.wait_for(r"hello (\d+)").group(1) == "42"
        assert child.wait_for(lambda line: line.endswith("42") and line) == "hello 42"
        assert child.wait_for("^to stderr$", stream="err")
        assert "hello 42" in child.text() and "to stderr" in child.describe()
    assert child.proc.poll() is not None  # the context manager kills it


def test_merged_stderr_lands_in_stdout():
    with _start("sleep", merge_stderr=True) as child:
        child.wait_for("^to stderr$")
        assert child.err == []


def test_a_child_that_exits_fails_the_wait_at_once_with_its_output():
    with _start("exit") as child:
        start = time.monotonic()
        with pytest.raises(WaitTimeout, match=r"exited with 3(.|\n)*hello 42"):
            child.wait_for("never printed", timeout=30)
        assert time.monotonic() - start < 20
        assert child.wait() == 3


def test_stop_asks_with_sigterm_first():
    child = _start("term")
    child.wait_for("hello")
    assert child.stop() == 7


def test_kill_takes_the_descendants_too():
    child = _start("grandchild")
    pid = int(child.wait_for(r"^pid (\d+)").group(1))
    child.kill()
    wait_until(
        lambda: not os.path.exists(f"/proc/{pid}") or "Z" in _state(pid),
        timeout=5,
        what="the grandchild gone",
    )


def _state(pid: int) -> str:
    try:
        with open(f"/proc/{pid}/stat") as f:
            return f.read().rsplit(")", 1)[1].split()[0]
    except OSError:
        return "Z"


def test_wait_for_master_names_a_master_that_exited_before_it_answered():
    import subprocess

    from ninjemys.testing import free_port, wait_for_master

    proc = subprocess.Popen([sys.executable, "-c", "raise SystemExit(3)"])
    proc.wait()
    start = time.monotonic()
    with pytest.raises(
        WaitTimeout, match=r"the test's master at http://localhost:\d+/ exited with 3 before it was ready"
    ):
        wait_for_master(f"http://localhost:{free_port()}/", proc, timeout=30.0, what="the test's master")
    assert time.monotonic() - start < 10.0  # at once, not after the timeout


def test_wait_for_master_waits_for_readiness_as_well_as_an_answer():
    from ninjemys.master.core import MasterThread
    from ninjemys.testing import wait_for_master

    with MasterThread() as uri:
        wait_for_master(uri, timeout=5.0)
        with pytest.raises(WaitTimeout, match="answered but was not ready within 0.3 s"):
            wait_for_master(uri, timeout=0.3, ready=lambda state: any(t == "/x" for t, _ in state[0]))


def test_catkin_workspace_writes_packages_and_keeps_the_callers_ros_environment_out(tmp_path, monkeypatch):
    from ninjemys.testing import CatkinWorkspace

    monkeypatch.setenv("ROS_PACKAGE_PATH", "/elsewhere/src")
    monkeypatch.setenv("ROS_MASTER_URI", "http://elsewhere:11311")
    monkeypatch.setenv("CMAKE_PREFIX_PATH", "/elsewhere/devel")
    ws = CatkinWorkspace(tmp_path)
    pkg = ws.package(
        "demo", {"package.xml": "<package/>", "scripts/run.py": "#!/bin/sh\n"}, ["scripts/run.py"]
    )
    assert pkg == tmp_path / "src" / "demo" and (pkg / "package.xml").read_text() == "<package/>"
    assert os.access(pkg / "scripts" / "run.py", os.X_OK) and not os.access(pkg / "package.xml", os.X_OK)
    env = ws.env("http://localhost:1234")
    assert (
        env["ROS_PACKAGE_PATH"] == str(tmp_path / "src") and env["ROS_MASTER_URI"] == "http://localhost:1234"
    )
    assert env["PYTHONPATH"] == str(tmp_path / "devel" / "lib" / "python3" / "dist-packages")
    assert env["CMAKE_PREFIX_PATH"] == str(tmp_path / "devel") and "ROS_MASTER_URI" not in ws.env()

"""The process supervisor on its own (no master): respawn, required, escalation, no orphans."""

from __future__ import annotations

import os
import sys
import threading
from pathlib import Path

from ninjemys.launch.runner import ProcessSpec, Supervisor

from .conftest import PKGS

SCRIPTS = PKGS / "corpus_run" / "scripts"


def spec(name: str, script: str, *args: str, **kw: object) -> ProcessSpec:
    return ProcessSpec(
        name=name,
        argv=[sys.executable, str(SCRIPTS / script), *args],
        env=dict(os.environ, PYTHONUNBUFFERED="1"),
        output="screen",
        **kw,  # type: ignore[arg-type]
    )


def alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    return True


def run_in_thread(sup: Supervisor) -> tuple[threading.Thread, list[int]]:
    result: list[int] = []
    thread = threading.Thread(target=lambda: result.append(sup.run()), daemon=True)
    thread.start()
    return thread, result


def test_respawn_restarts_a_crashing_node() -> None:
    lines: list[str] = []
    sup = Supervisor(
        [spec("crash-1", "crasher.py", "0", respawn=True, respawn_delay=0.05)], write=lines.append
    )
    starts: list[str] = []

    def on_event(kind: str, name: str) -> None:
        if kind == "started":
            starts.append(name)
            if len(starts) == 4:
                sup.request_shutdown()

    sup.on_event = on_event
    thread, result = run_in_thread(sup)
    thread.join(60)
    assert not thread.is_alive()
    assert result == [0]
    assert sup.respawn_count("crash-1") >= 3
    assert sum("restarting process" in line for line in lines) >= 3
    assert any("process has died" in line and "exit code 3" in line for line in lines)


def test_required_node_death_stops_everything_with_failure() -> None:
    lines: list[str] = []
    sup = Supervisor(
        [spec("sleeper-1", "sleeper.py"), spec("crash-2", "crasher.py", "0.2", required=True)],
        write=lines.append,
    )
    thread, result = run_in_thread(sup)
    thread.join(60)
    assert not thread.is_alive()
    assert result == [1]
    text = "".join(lines)
    assert "REQUIRED process [crash-2] has died!" in text
    pids = [p.popen.pid for p in sup.procs if p.popen is not None]
    assert pids and not any(alive(pid) for pid in pids)


def test_screen_output_is_prefixed_per_node_when_asked() -> None:
    lines: list[str] = []
    sup = Supervisor(
        [spec("sleeper-1", "sleeper.py", "__name:=alpha")], write=lines.append, prefix_output=True
    )
    sup.on_event = lambda kind, name: None
    thread, result = run_in_thread(sup)
    deadline_hit = threading.Event()

    def stop_when_ready() -> None:
        while not any("alpha ready" in line for line in lines):
            if deadline_hit.wait(0.02):
                return
        sup.request_shutdown()

    stopper = threading.Thread(target=stop_when_ready, daemon=True)
    stopper.start()
    thread.join(60)
    deadline_hit.set()
    assert result == [0]
    assert "[sleeper-1] alpha ready\n" in lines


def test_sigint_ignoring_node_is_escalated_to_sigterm() -> None:
    lines: list[str] = []
    holder: list[Supervisor] = []

    def write(text: str) -> None:
        lines.append(text)
        if "stubborn ready" in text:
            holder[0].request_shutdown()

    sup = Supervisor(
        [spec("stubborn-1", "stubborn.py", sigint_timeout=0.3, sigterm_timeout=0.5)],
        write=write,
        prefix_output=True,
    )
    holder.append(sup)
    thread, result = run_in_thread(sup)
    thread.join(60)
    assert not thread.is_alive() and result == [0]
    assert any("stubborn ready" in line for line in lines)
    assert any("escalating to SIGTERM" in line for line in lines)
    assert not alive(sup.procs[0].popen.pid)  # type: ignore[union-attr]


def test_supervisor_messages_go_to_the_launch_log_but_node_output_does_not() -> None:
    lines: list[str] = []
    logged: list[str] = []
    sup = Supervisor(
        [spec("crash-1", "crasher.py", "0")], write=lines.append, log=logged.append, prefix_output=True
    )
    assert sup.run() == 0
    assert any("crasher running" in line for line in lines)
    assert not any("crasher running" in line for line in logged)
    assert any("process[crash-1]: started with pid" in line for line in logged)


def test_log_output_goes_to_a_file(tmp_path: Path) -> None:
    lines: list[str] = []
    s = spec("crash-1", "crasher.py", "0")
    s.output = "log"
    s.log_dir = tmp_path
    sup = Supervisor([s], write=lines.append)
    assert sup.run() == 0
    assert (tmp_path / "crash-1-stdout.log").read_text() == "crasher running\n"
    assert not any("crasher running" in line for line in lines)
    assert any("all processes on machine have died" in line for line in lines)


def test_required_node_finishing_cleanly_ends_launch_without_failure() -> None:
    lines: list[str] = []
    done = ProcessSpec(
        name="done-2", argv=[sys.executable, "-c", "pass"], env=dict(os.environ), required=True
    )
    sup = Supervisor([spec("sleeper-1", "sleeper.py"), done], write=lines.append)
    thread, result = run_in_thread(sup)
    thread.join(60)
    assert result == [0]
    assert "REQUIRED process [done-2] has died!" in "".join(lines)
    assert not alive(sup.procs[0].popen.pid)  # type: ignore[union-attr]


def test_second_interrupt_kills_at_once() -> None:
    lines: list[str] = []
    holder: list[Supervisor] = []

    def write(text: str) -> None:
        lines.append(text)
        if "stubborn ready" in text:
            holder[0].request_shutdown()
        if "killing on exit" in text:
            holder[0].request_shutdown()

    sup = Supervisor(
        [spec("stubborn-1", "stubborn.py", sigint_timeout=60, sigterm_timeout=60)],
        write=write,
        prefix_output=True,
    )
    holder.append(sup)
    thread, result = run_in_thread(sup)
    thread.join(30)
    assert not thread.is_alive() and result == [0]
    assert any("second interrupt" in line for line in lines)
    assert not any("escalating" in line for line in lines)
    assert not alive(sup.procs[0].popen.pid)  # type: ignore[union-attr]


def test_shutdown_stops_the_nodes_in_reverse_start_order() -> None:
    """ROS 1's roslaunch queues its kills last-started first ("killing on exit" lines in that order)."""
    lines: list[str] = []
    names = ["first", "second", "third"]
    sup = Supervisor(
        [spec(f"{n}-{i}", "sleeper.py", f"__name:={n}") for i, n in enumerate(names, 1)],
        write=lines.append,
        prefix_output=True,
    )
    thread, result = run_in_thread(sup)
    stop = threading.Event()

    def stop_when_ready() -> None:
        while not all(any(f"{n} ready" in line for line in lines) for n in names):
            if stop.wait(0.02):
                return
        sup.request_shutdown()

    threading.Thread(target=stop_when_ready, daemon=True).start()
    thread.join(60)
    stop.set()
    assert result == [0]
    killed = [line.split("]")[0].lstrip("[") for line in lines if "killing on exit" in line]
    assert killed == ["third-3", "second-2", "first-1"]

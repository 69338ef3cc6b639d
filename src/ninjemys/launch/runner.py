"""The process supervisor: start the plan's nodes, watch them, respawn, shut down promptly.

One thread (the caller's) runs everything from one selector: a pidfd per child (readable when it
exits) and the signal wakeup fd. A node's output goes where ROS 1's roslaunch sends it: with
output="screen" the node writes to roslaunch's own stdout and stderr, unchanged (scripts that parse
it keep working); with output="log" its stdout goes to ``<name>-stdout.log`` and its stderr to the
screen. With ``prefix_output`` (``roslaunch --prefix-output``, ``NINJEMYS_LAUNCH_PREFIX=1``) both
pipes are read here instead and each line is printed with a ``[name] `` prefix, so twenty nodes'
output stays readable. Timers (respawn delays, shutdown
escalation) are the selector timeout. No polling loops, no thread per node.

Shutdown (Ctrl-C, SIGTERM, a required node's death, or the master's death): SIGINT to every
node's process group at once (in reverse start order, as ROS 1 queues its kills), SIGTERM after the node's ``sigint_timeout`` (default
:data:`DEFAULT_SIGINT_TIMEOUT`, ROS 1: 15 s), SIGKILL after :data:`DEFAULT_SIGTERM_TIMEOUT` more
(ROS 1: 2 s); the auto-started master is stopped last, after the nodes had a chance to unregister.
"""

from __future__ import annotations

import os
import selectors
import shlex
import shutil
import signal
import subprocess
import sys
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import IO

from ninjemys.errors import LaunchError
from ninjemys.launch.plan import Machine, NodeSpec

DEFAULT_SIGINT_TIMEOUT = 2.0
DEFAULT_SIGTERM_TIMEOUT = 1.0


@dataclass
class ProcessSpec:
    """One process to supervise: what to run and how (derived from a NodeSpec, or the core)."""

    name: str
    argv: list[str]
    env: dict[str, str]
    cwd: str | None = None
    output: str = "log"
    respawn: bool = False
    respawn_delay: float = 0.0
    required: bool = False
    sigint_timeout: float = DEFAULT_SIGINT_TIMEOUT
    sigterm_timeout: float = DEFAULT_SIGTERM_TIMEOUT
    log_dir: Path | None = None
    #: a process started by someone else (the auto-started master): adopted, stopped last
    popen: subprocess.Popen | None = None
    is_core: bool = False


@dataclass
class _Running:
    spec: ProcessSpec
    popen: subprocess.Popen | None = None
    pidfd: int | None = None
    streams: dict[int, tuple[IO[bytes], str]] = field(default_factory=dict)
    partial: dict[int, bytes] = field(default_factory=dict)
    respawns: int = 0
    restart_at: float | None = None
    stop_stage: int = 0
    stop_deadline: float | None = None
    log_file: IO[bytes] | None = None
    exit_code: int | None = None


class Supervisor:
    """Runs :class:`ProcessSpec` s until shutdown; ``run()`` returns the launch's exit status."""

    def __init__(
        self,
        specs: list[ProcessSpec],
        write: Callable[[str], None] | None = None,
        log: Callable[[str], None] | None = None,
        prefix_output: bool = False,
    ) -> None:
        self.procs = [_Running(spec) for spec in specs]
        #: read the nodes' output and print it line by line behind ``[name] `` (else: passed through)
        self.prefix_output = prefix_output
        #: receives the supervisor's own messages (not node output): the roslaunch log file
        self._log = log
        self.selector = selectors.DefaultSelector()
        self._write = write or _stdout_write
        self._output_broken = False
        self.failed = False
        self.shutting_down = False
        self._wake_r, self._wake_w = os.pipe()
        os.set_blocking(self._wake_r, False)
        os.set_blocking(self._wake_w, False)
        self.selector.register(self._wake_r, selectors.EVENT_READ, ("wake", None))
        #: optional observer of ("started" | "exited", process name) events, called on the supervising thread
        self.on_event: Callable[[str, str], None] | None = None

    def write(self, text: str) -> None:
        """Print a supervisor message (also to the launch log)."""
        if self._log is not None:
            try:
                self._log(text)
            except (OSError, ValueError):
                self._log = None
        self._print(text)

    def _print(self, text: str) -> None:
        """Print to the terminal; a closed stdout (``| head``) never stops supervision."""
        if self._output_broken:
            return
        try:
            self._write(text)
        except (BrokenPipeError, OSError, ValueError):
            self._output_broken = True

    # -- starting --------------------------------------------------------------------------------
    def _start(self, proc: _Running) -> None:
        spec = proc.spec
        if spec.popen is not None and proc.popen is None:
            proc.popen = spec.popen
        else:
            # None: the node inherits roslaunch's stream, as in ROS 1
            stdout: int | IO[bytes] | None = subprocess.PIPE if self.prefix_output else None
            stderr: int | None = subprocess.PIPE if self.prefix_output else None
            if spec.output == "log" and spec.log_dir is not None:
                spec.log_dir.mkdir(parents=True, exist_ok=True)
                proc.log_file = open(spec.log_dir / f"{spec.name}-stdout.log", "ab")  # noqa: SIM115 - closed on exit
                stdout = proc.log_file
            if not spec.is_core and not _runnable(spec.argv[0], spec.env):
                self._fatal_launch(proc)
                return
            if not spec.is_core and not _exec_format_ok(spec.argv[0]):
                # ROS 1's FatalProcessLaunch for ENOEXEC: a script without its "#!" line
                self.write(
                    f"RLException: Unable to launch [{spec.name}]. \n"
                    "If it is a script, you may be missing a '#!' declaration at the top.\n"
                )
                proc.exit_code = 126
                self.failed = True
                self.shutdown()
                return
            try:
                # stdin is roslaunch's own, as in ROS 1: keyboard teleops and input() prompts started
                # by a launch file (turtlebot3_teleop_key.launch) read the terminal roslaunch runs in
                proc.popen = subprocess.Popen(
                    [*DEATH_WRAPPER, *spec.argv],
                    stdin=None,
                    stdout=stdout,
                    stderr=stderr,
                    env=spec.env,
                    cwd=spec.cwd,
                    start_new_session=True,
                )
            except OSError as exc:
                self.write(f"ERROR: cannot launch node [{spec.name}]: {exc.strerror}: {spec.argv[0]}\n")
                proc.exit_code = 127
                if spec.required:
                    self._required_died(proc)
                return
            for stream, label in ((proc.popen.stdout, "stdout"), (proc.popen.stderr, "stderr")):
                if stream is not None:
                    os.set_blocking(stream.fileno(), False)
                    proc.streams[stream.fileno()] = (stream, label)
                    self.selector.register(stream.fileno(), selectors.EVENT_READ, ("out", proc))
        proc.pidfd = os.pidfd_open(proc.popen.pid)
        self.selector.register(proc.pidfd, selectors.EVENT_READ, ("exit", proc))
        proc.exit_code = None
        if not spec.is_core:
            self.write(f"process[{spec.name}]: started with pid [{proc.popen.pid}]\n")
        self._event("started", spec.name)

    def _fatal_launch(self, proc: _Running) -> None:
        """The program a node's command starts with (usually its launch-prefix) does not exist: ROS 1
        raises FatalProcessLaunch, starts nothing more, stops what it started and exits with 1."""
        self.write(
            "RLException: Roslaunch got a 'No such file or directory' error while attempting to run:\n\n"
            f"{' '.join(proc.spec.argv)}\n\n"
            "Please make sure that all the executables in this command exist and have\n"
            "executable permission. This is often caused by a bad launch-prefix.\n"
        )
        proc.exit_code = 127
        self.failed = True
        self.shutdown()

    def _event(self, kind: str, name: str) -> None:
        if self.on_event is not None:
            self.on_event(kind, name)

    # -- output ----------------------------------------------------------------------------------
    def _pump(self, fd: int, proc: _Running) -> bool:
        """Read what is available on one output pipe; False once nothing more is there right now."""
        stream, _label = proc.streams[fd]
        try:
            data = os.read(fd, 65536)
        except BlockingIOError:
            return False
        except OSError:
            data = b""
        if not data:
            self.selector.unregister(fd)
            del proc.streams[fd]
            rest = proc.partial.pop(fd, b"")
            if rest:
                self._emit(proc, rest)
            stream.close()
            return False
        buf = proc.partial.get(fd, b"") + data
        *lines, last = buf.split(b"\n")
        proc.partial[fd] = last
        for line in lines:
            self._emit(proc, line)
        return True

    def _emit(self, proc: _Running, line: bytes) -> None:
        self._print(f"[{proc.spec.name}] {line.decode('utf-8', errors='replace')}\n")

    def _drain(self, proc: _Running) -> None:
        """After an exit: print what is left in the pipes without ever blocking."""
        for fd in list(proc.streams):
            while fd in proc.streams and self._pump(fd, proc):
                pass

    # -- exits -----------------------------------------------------------------------------------
    def _exited(self, proc: _Running) -> None:
        assert proc.popen is not None and proc.pidfd is not None
        self.selector.unregister(proc.pidfd)
        os.close(proc.pidfd)
        proc.pidfd = None
        code = proc.popen.wait()
        proc.exit_code = code
        self._drain(proc)
        if proc.log_file is not None:
            proc.log_file.close()
            proc.log_file = None
        spec = proc.spec
        self._event("exited", spec.name)
        if self.shutting_down:
            return
        cmd = " ".join(shlex.quote(a) for a in spec.argv)
        if spec.is_core:
            self.write(
                f"[master] the master process has died [pid {proc.popen.pid}, exit code {code}]; shutting down\n"
            )
            self.failed = True
            self.shutdown()
            return
        if code == 0:
            self.write(f"[{spec.name}] process has finished cleanly\n")
        else:
            self.write(
                f"[{spec.name}] process has died [pid {proc.popen.pid}, exit code {code}, cmd {cmd}].\n"
            )
            if spec.output == "log" and spec.log_dir is not None:
                self.write(f"log file: {spec.log_dir / (spec.name + '-stdout.log')}\n")
        if spec.required:
            self._required_died(proc, failed=code != 0)
        elif spec.respawn:
            proc.restart_at = time.monotonic() + max(spec.respawn_delay, 0.0)
        elif all(p.exit_code is not None and not p.spec.respawn for p in self.procs if not p.spec.is_core):
            if not any(p.spec.is_core for p in self.procs):
                self.write("all processes on machine have died, roslaunch will exit\n")
                self.shutdown()

    def _required_died(self, proc: _Running, failed: bool = True) -> None:
        """A required node ended: the whole launch ends, failing unless the node exited with 0."""
        bar = "=" * 80
        self.write(f"{bar}\nREQUIRED process [{proc.spec.name}] has died!\nInitiating shutdown!\n{bar}\n")
        self.failed = self.failed or failed
        self.shutdown()

    # -- shutdown --------------------------------------------------------------------------------
    def shutdown(self) -> None:
        """Begin stopping everything (idempotent); ``run()`` returns once all processes are gone."""
        if self.shutting_down:
            return
        self.shutting_down = True
        now = time.monotonic()
        # last started, first stopped: ROS 1's process monitor queues its parallel kills in reverse
        for proc in reversed(self.procs):
            proc.restart_at = None
            if proc.spec.is_core:
                continue
            if proc.pidfd is not None:
                self.write(f"[{proc.spec.name}] killing on exit\n")
            self._signal(proc, signal.SIGINT)
            proc.stop_stage = 1
            proc.stop_deadline = now + proc.spec.sigint_timeout

    def request_shutdown(self) -> None:
        """Thread- and signal-safe: wake the loop and make it shut down."""
        try:
            os.write(self._wake_w, b"s")
        except (BlockingIOError, OSError):
            pass

    def _kill_now(self) -> None:
        """A second Ctrl-C during shutdown: no more waiting, SIGKILL every process still running."""
        self.write("second interrupt: killing every remaining process now\n")
        for proc in self.procs:
            self._signal(proc, signal.SIGKILL)
            proc.stop_stage = 3
            proc.stop_deadline = None

    def _signal(self, proc: _Running, sig: int) -> None:
        if proc.popen is None or proc.exit_code is not None or proc.pidfd is None:
            return
        try:
            os.killpg(proc.popen.pid, sig)
        except (ProcessLookupError, PermissionError):
            try:
                proc.popen.send_signal(sig)
            except ProcessLookupError:
                pass

    def _escalate(self, now: float) -> None:
        nodes_alive = False
        for proc in self.procs:
            if proc.spec.is_core or proc.pidfd is None:
                continue
            nodes_alive = True
            if proc.stop_deadline is not None and now >= proc.stop_deadline:
                if proc.stop_stage == 1:
                    self.write(f"[{proc.spec.name}] escalating to SIGTERM\n")
                    self._signal(proc, signal.SIGTERM)
                    proc.stop_stage = 2
                    proc.stop_deadline = now + proc.spec.sigterm_timeout
                elif proc.stop_stage == 2:
                    self.write(f"[{proc.spec.name}] escalating to SIGKILL\n")
                    self._signal(proc, signal.SIGKILL)
                    proc.stop_stage = 3
                    proc.stop_deadline = None
        if not nodes_alive:
            for proc in self.procs:
                if proc.spec.is_core and proc.pidfd is not None and proc.stop_stage == 0:
                    self._signal(proc, signal.SIGINT)
                    proc.stop_stage = 1
                    proc.stop_deadline = now + proc.spec.sigint_timeout
                elif (
                    proc.spec.is_core
                    and proc.pidfd is not None
                    and proc.stop_deadline
                    and now >= proc.stop_deadline
                ):
                    self._signal(proc, signal.SIGKILL)
                    proc.stop_deadline = None

    def _next_timeout(self, now: float) -> float | None:
        times = [p.restart_at for p in self.procs if p.restart_at is not None]
        times += [p.stop_deadline for p in self.procs if p.stop_deadline is not None and p.pidfd is not None]
        if not times:
            return None
        return max(0.0, min(times) - now)

    # -- main loop -------------------------------------------------------------------------------
    def run(self) -> int:
        """Start every process, supervise until shutdown, return 1 if a required node failed.

        Whatever happens inside (even a bug), no child outlives this call: they are killed.
        """
        try:
            return self._run()
        finally:
            self.kill_all()

    def kill_all(self) -> None:
        """SIGKILL every process group still alive and reap it (the last-resort cleanup)."""
        for proc in self.procs:
            if proc.popen is not None and proc.popen.poll() is None:
                try:
                    os.killpg(proc.popen.pid, signal.SIGKILL)
                except (ProcessLookupError, PermissionError):
                    proc.popen.kill()
                proc.popen.wait()

    def _run(self) -> int:
        for proc in self.procs:
            if self.shutting_down:
                break
            self._start(proc)
        while True:
            now = time.monotonic()
            if self.shutting_down:
                self._escalate(now)
                if all(p.pidfd is None for p in self.procs):
                    break
            for proc in self.procs:
                if proc.restart_at is not None and now >= proc.restart_at and not self.shutting_down:
                    proc.restart_at = None
                    proc.respawns += 1
                    self.write(f"[{proc.spec.name}] restarting process\n")
                    self._start(proc)
            timeout = self._next_timeout(time.monotonic())
            for key, _mask in self.selector.select(timeout):
                kind, proc = key.data
                if kind == "wake":
                    try:
                        os.read(self._wake_r, 512)
                    except BlockingIOError:
                        pass
                    if self.shutting_down:
                        self._kill_now()
                    else:
                        self.shutdown()
                elif kind == "out":
                    if key.fd in proc.streams:
                        self._pump(key.fd, proc)
                elif kind == "exit" and proc.pidfd == key.fd:
                    self._exited(proc)
        self.write(
            "shutting down processing monitor...\n... shutting down processing monitor complete\ndone\n"
        )
        for proc in self.procs:
            self._drain(proc)
            for fd, (stream, _label) in list(proc.streams.items()):
                self.selector.unregister(fd)
                stream.close()
            proc.streams.clear()
            if proc.log_file is not None:
                proc.log_file.close()
                proc.log_file = None
        self.selector.close()
        os.close(self._wake_r)
        os.close(self._wake_w)
        return 1 if self.failed else 0

    def respawn_count(self, name: str) -> int:
        return next(p.respawns for p in self.procs if p.spec.name == name)


def _runnable(program: str, env: dict[str, str]) -> bool:
    """Whether exec would find ``program``: a path that is an executable file, or a name on PATH."""
    if "/" in program:
        return os.path.isfile(program) and os.access(program, os.X_OK)
    return shutil.which(program, path=env.get("PATH", os.defpath)) is not None


def _exec_format_ok(program: str) -> bool:
    """False for a file exec would refuse with ENOEXEC: neither ELF nor starting with ``#!``
    (a program found on PATH by name is left to exec)."""
    if "/" not in program:
        return True
    try:
        with open(program, "rb") as f:
            head = f.read(4)
    except OSError:
        return True
    return head.startswith((b"#!", b"\x7fELF"))


def _stdout_write(text: str) -> None:
    sys.stdout.write(text)
    sys.stdout.flush()


#: Prefix that makes a child get SIGTERM when roslaunch dies, even by SIGKILL, so no node is ever
#: orphaned. util-linux's setpriv sets PR_SET_PDEATHSIG and execs the node (same pid): ~1 ms per
#: process, where a Python preexec_fn costs ~25 ms (it forces fork() of the whole interpreter).
DEATH_WRAPPER: list[str] = (
    [shutil.which("setpriv") or "setpriv", "--pdeathsig", "TERM", "--"] if shutil.which("setpriv") else []
)


def remote_command(
    machine: Machine, argv: list[str], env: dict[str, str], timeout: float = 10.0
) -> list[str]:
    """ssh argv running ``argv`` on ``machine`` with ``env`` (every variable of it, set before the
    machine's env-loader runs); LaunchError naming the machine if unreachable."""
    target = f"{machine.user}@{machine.address}" if machine.user else machine.address
    base = [
        "ssh",
        "-o",
        "BatchMode=yes",
        "-o",
        f"ConnectTimeout={int(machine.timeout or timeout)}",
        "-p",
        str(machine.ssh_port),
    ]
    try:
        probe = subprocess.run(
            [*base, target, "true"],
            stdin=subprocess.DEVNULL,
            capture_output=True,
            timeout=(machine.timeout or timeout) + 5,
            check=False,
        )
    except FileNotFoundError:
        raise LaunchError(
            f"machine [{machine.name}] ({machine.address}) needs ssh, which is not installed"
        ) from None
    except subprocess.TimeoutExpired:
        raise LaunchError(f"machine [{machine.name}] ({machine.address}): ssh timed out") from None
    if probe.returncode != 0:
        reason = probe.stderr.decode(errors="replace").strip().splitlines()
        raise LaunchError(
            f"cannot reach machine [{machine.name}] at {target} over ssh (port {machine.ssh_port}): "
            f"{reason[-1] if reason else f'exit code {probe.returncode}'}"
        )
    assignments = [f"{k}={shlex.quote(v)}" for k, v in env.items()]
    loader = shlex.split(machine.env_loader) if machine.env_loader else []
    remote = " ".join(
        ["env", *assignments, *(shlex.quote(a) for a in loader), *(shlex.quote(a) for a in argv)]
    )
    return [*base, "-tt", target, remote]


def node_process_name(spec: NodeSpec, counter: int) -> str:
    base = spec.name.rsplit("/", 1)[-1] or spec.type
    return f"{base}-{counter}"

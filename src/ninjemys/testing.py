"""Public test helpers: free ports, locating Debian's real ROS 1 for comparison tests, a master or a node
in a child process (:func:`run_master`, :func:`run_real_master`, :func:`run_real_roscore`,
:class:`NodeProcess`) and polling waits (:func:`wait_until`, :func:`wait_for_master`).

Kept dependency-free so user test suites (and ours) can import it without starting anything.
"""

from __future__ import annotations

import contextlib
import os
import re
import signal
import subprocess
import threading
import time
from collections.abc import Callable, Iterator, Sequence
from pathlib import Path
from typing import IO, Any

from ninjemys.commands import command_path
from ninjemys.errors import NinjemysError
from ninjemys.net.addresses import free_port as free_port  # re-exported: tests and users take it from here

#: Debian's real ROS 1 runs under the system interpreter, never the project's venv.
ROS1_PYTHON = "/usr/bin/python3"
ROS1_BIN = Path("/usr/bin")


def have_ros1() -> bool:
    """True when Debian's ROS 1 (rospy + rosmaster under /usr/bin/python3) is installed."""
    return Path(ROS1_PYTHON).exists() and Path("/usr/lib/python3/dist-packages/rospy").is_dir()


def ros1_env(master_uri: str, **extra: str) -> dict[str, str]:
    """An environment for running real ROS 1 programs: no venv, no ninjemys on the path."""
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "VIRTUAL_ENV", "PYTHONHOME")}
    env["PATH"] = "/usr/bin:/bin:/usr/sbin:/sbin"
    env["ROS_MASTER_URI"] = master_uri
    env.setdefault("ROS_HOSTNAME", "localhost")
    env.update(extra)
    return env


def ros1_built_interfaces(dest: str | os.PathLike[str]) -> Path:
    """A copy of the shipped interface packages as a ROS 1 build leaves them, for real rosmsg/rospack.

    catkin runs actionlib_msgs' genaction.py over every ``.action`` and writes the seven generated
    ``.msg`` files into the package's share ``msg/``; real tools list and show them from there. This
    runs Debian's own genaction.py the same way, so a comparison against real ROS 1 sees what a built
    installation holds. Returns the directory to put on ``ROS_PACKAGE_PATH``.
    """
    import shutil

    from ninjemys.idl.search import SHIPPED_ROOT

    root = Path(dest) / "interfaces"
    shutil.copytree(SHIPPED_ROOT, root)
    for action in sorted(root.glob("*/action/*.action")):
        subprocess.run(
            [
                ROS1_PYTHON,
                "/usr/lib/actionlib_msgs/genaction.py",
                str(action),
                "-o",
                str(action.parent.parent / "msg"),
            ],
            env=ros1_env("http://localhost:11311"),
            capture_output=True,
            check=True,
            timeout=60,
        )
    return root


def ninjemys_bin(command: str) -> str:
    """Full path of one of our console scripts (the venv's bin/, next to the running interpreter)."""
    return command_path(command)


def FakeClock(start: float = 0.0) -> Any:  # noqa: N802 - reads as a class at call sites
    """A simulated ROS clock that a test drives by hand (``clock.advance(0.5)``, ``clock.set(3.0)``).

    Returns a :class:`ninjemys.node.clock.FakeClock`; imported on call so this module stays light.
    """
    from ninjemys.node.clock import FakeClock as _FakeClock

    return _FakeClock(start)


def reset_rospy() -> None:
    """Shut down the rospy node of this process (if any) and forget all of rospy's state, in-process.

    rospy allows one ``init_node`` per process; after this, the next ``rospy.init_node`` starts a
    new node, so rospy tests need no subprocess each. User shutdown hooks run first, as on a real
    shutdown; handles (Publishers, Subscribers, Services) of the old node stay unregistered.
    Typical use is a fixture::

        @pytest.fixture
        def rospy_node(master_uri, monkeypatch):
            monkeypatch.setenv("ROS_MASTER_URI", master_uri)
            yield
            ninjemys.testing.reset_rospy()
    """
    import sys

    core = sys.modules.get("rospy.core")
    if core is not None:  # rospy never imported: nothing to reset
        core._reset()


class WaitTimeout(NinjemysError, AssertionError):
    """A test's wait ran out: an AssertionError, so pytest reports it as the test's failure."""


def wait_for_master(
    uri: str,
    proc: subprocess.Popen[bytes] | None = None,
    timeout: float = 20.0,
    ready: Callable[[Any], bool] | None = None,
    what: str = "the master",
) -> None:
    """Return once the master at ``uri`` answers ``getSystemState`` (and ``ready(state)`` holds, e.g. a
    topic is registered). Raises :class:`WaitTimeout` naming ``what`` when ``proc`` (the master's process,
    if the caller started it) exits first or ``timeout`` seconds pass: one wait for every kind of master
    a test starts (ours, Debian's rosmaster or roscore). A master started with a secret this process
    does not hold is up once it refuses the call for that reason."""
    from ninjemys.net import auth

    deadline = time.monotonic() + timeout
    answered = False
    while True:
        try:
            # the master's reply is XML-RPC data (typeshed's union of every wire type): a triple here
            reply: Any = auth.server_proxy(uri).getSystemState("/wait_for_master")
            answered = True
            if reply[0] == 1 and (ready is None or ready(reply[2])):
                return
            if ready is None and reply[0] == -1 and "authentication failed" in str(reply[1]):
                return  # up, but started with a secret this process does not hold: a refusal is its answer
        except OSError:
            pass
        if proc is not None and proc.poll() is not None:
            raise WaitTimeout(f"{what} at {uri} exited with {proc.returncode} before it was ready")
        if time.monotonic() > deadline:
            state = "answered but was not ready" if answered else "did not answer"
            raise WaitTimeout(f"{what} at {uri} {state} within {timeout:g} s")
        time.sleep(0.02)


@contextlib.contextmanager
def run_master(
    port: int | None = None, env: dict[str, str] | None = None, timeout: float = 20.0
) -> Iterator[str]:
    """Start our ``roscore`` on a free port, yield its URI once it answers, kill it afterwards.

    ``env`` replaces the child's environment (ROS_HOME and ROS_LOG_DIR are inherited by default,
    so logs land in the test's own directory); its output is discarded.
    """
    port = port or free_port()
    uri = f"http://localhost:{port}/"
    child_env = dict(os.environ if env is None else env)
    child_env.setdefault("ROS_HOSTNAME", "localhost")
    child_env["ROS_MASTER_URI"] = uri
    proc = subprocess.Popen(
        [ninjemys_bin("roscore"), "-p", str(port)],
        env=child_env,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
        stdin=subprocess.DEVNULL,
    )
    try:
        wait_for_master(uri, proc, timeout, what=f"roscore -p {port}")
        yield uri
    finally:
        proc.kill()
        proc.wait()


@contextlib.contextmanager
def run_real_master(host: str = "localhost", timeout: float = 20.0) -> Iterator[str]:
    """Debian's ``rosmaster --core`` (no rosout) on a free port under the system Python; yields its URI
    once it answers, kills it afterwards. ``host`` names it in the URI and in ``ROS_HOSTNAME``."""
    port = free_port()
    uri = f"http://{host}:{port}/"
    proc = subprocess.Popen(
        [ROS1_PYTHON, str(ROS1_BIN / "rosmaster"), "--core", "-p", str(port)],
        env=ros1_env(uri, ROS_HOSTNAME=host),
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
        stdin=subprocess.DEVNULL,
    )
    try:
        wait_for_master(uri, proc, timeout, what=f"/usr/bin/rosmaster -p {port}")
        yield uri
    finally:
        proc.kill()
        proc.wait()


def descendants(pid: int) -> list[int]:
    """Every live descendant of ``pid`` (from /proc), children before grandchildren.

    Needed because roslaunch puts each child (rosmaster, rosout) in its own session, so killing the
    parent's process group leaves them running.
    """
    children: dict[int, list[int]] = {}
    for entry in Path("/proc").iterdir():
        if not entry.name.isdigit():
            continue
        try:
            stat = (entry / "stat").read_text()
        except OSError:
            continue
        ppid = int(stat.rsplit(")", 1)[1].split()[1])
        children.setdefault(ppid, []).append(int(entry.name))
    found: list[int] = []
    frontier = [pid]
    while frontier:
        nxt = []
        for parent in frontier:
            for child in children.get(parent, []):
                found.append(child)
                nxt.append(child)
        frontier = nxt
    return found


def kill_tree(proc: Any) -> None:
    """SIGKILL a Popen'd process and all of its descendants, then reap it."""

    for pid in [*descendants(proc.pid), proc.pid]:
        try:
            os.kill(pid, signal.SIGKILL)
        except ProcessLookupError:
            pass
    proc.wait()


@contextlib.contextmanager
def run_real_roscore(ros_home: str | os.PathLike[str], timeout: float = 30.0) -> Iterator[str]:
    """Debian's /usr/bin/roscore on a free port; yields its URI once /rosout is up; kills the whole tree."""

    port = free_port()
    uri = f"http://localhost:{port}/"
    proc = subprocess.Popen(
        ["/usr/bin/roscore", "-p", str(port)],
        env=ros1_env(uri, ROS_HOME=str(ros_home)),
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
        stdin=subprocess.DEVNULL,
        start_new_session=True,
    )
    try:
        wait_for_master(
            uri,
            proc,
            timeout,
            ready=lambda state: any(topic == "/rosout_agg" for topic, _ in state[0]),
            what=f"/usr/bin/roscore -p {port} (with /rosout)",
        )
        yield uri
    finally:
        kill_tree(proc)


def wait_until(
    predicate: Callable[[], Any], timeout: float = 20.0, what: str = "condition", step: float = 0.05
) -> Any:
    """Poll ``predicate`` every ``step`` seconds until it returns something truthy, and return that.

    For tests only, where the code under test offers no event to wait on (another process, the
    master's state). Raises :class:`WaitTimeout` naming ``what`` after ``timeout`` seconds; the
    predicate is asked once more at the deadline, so a slow machine that got there late still passes.
    """
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        value = predicate()
        if value:
            return value
        time.sleep(step)
    value = predicate()
    if value:
        return value
    raise WaitTimeout(f"timed out after {timeout:g} s waiting for {what}")


Match = Callable[[str], Any]


class NodeProcess:
    """A node (ours, real ROS 1's, any command) in a child process, its output collected line by line.

    Reader threads collect stdout and stderr (``stderr=None``: merged into stdout), so the child never
    blocks on a full pipe and a test can wait for a line without reading. Use it as a context manager
    or call :meth:`stop`; both leave no process behind (:meth:`stop` asks with SIGTERM, then kills the
    whole tree, as roslaunch's children live in their own sessions).
    """

    def __init__(
        self,
        cmd: Sequence[str],
        env: dict[str, str] | None = None,
        cwd: str | os.PathLike[str] | None = None,
        merge_stderr: bool = False,
    ) -> None:
        self.cmd = list(cmd)
        self.proc = subprocess.Popen(
            self.cmd,
            env=env,
            cwd=cwd,
            stdout=subprocess.PIPE,
            stderr=subprocess.STDOUT if merge_stderr else subprocess.PIPE,
            stdin=subprocess.DEVNULL,
        )
        self.out: list[str] = []
        self.err: list[str] = []
        self._cond = threading.Condition()
        streams: list[tuple[IO[bytes] | None, list[str]]] = [(self.proc.stdout, self.out)]
        if not merge_stderr:
            streams.append((self.proc.stderr, self.err))
        self._readers = [
            threading.Thread(target=self._read, args=(stream, sink), daemon=True, name="NodeProcess reader")
            for stream, sink in streams
        ]
        for reader in self._readers:
            reader.start()

    @property
    def pid(self) -> int:
        return self.proc.pid

    def _read(self, stream: IO[bytes] | None, sink: list[str]) -> None:
        if stream is None:
            return
        for raw in iter(stream.readline, b""):
            with self._cond:
                sink.append(raw.decode("utf-8", "replace").rstrip("\n"))
                self._cond.notify_all()
        stream.close()
        with self._cond:
            self._cond.notify_all()

    def text(self) -> str:
        """Everything printed on stdout so far (with stderr when merged), one line per line."""
        with self._cond:
            return "\n".join(self.out)

    def wait_for(self, pattern: str | Match, timeout: float = 15.0, stream: str = "out") -> Any:
        """The first line of stdout (``stream="err"``: stderr) that matches: a regex ``pattern`` gives its
        ``re.Match``, a callable gives its truthy result. Fails the test (:class:`WaitTimeout`, with the
        last lines of both streams) after ``timeout`` seconds or once the child has exited and its output
        is read."""
        match: Match = re.compile(pattern).search if isinstance(pattern, str) else pattern
        sink = self.out if stream == "out" else self.err
        deadline = time.monotonic() + timeout
        seen = 0
        with self._cond:
            while True:
                for line in sink[seen:]:
                    found = match(line)
                    if found:
                        return found
                seen = len(sink)
                left = deadline - time.monotonic()
                ended = self.proc.poll() is not None and not any(r.is_alive() for r in self._readers)
                if left <= 0 or ended:
                    why = f"exited with {self.proc.returncode}" if ended else f"nothing within {timeout:g} s"
                    raise WaitTimeout(
                        f"{self.cmd}: no line matching {pattern!r} on std{stream} ({why})\n"
                        f"stdout: {self.out[-20:]}\nstderr: {self.err[-20:]}"
                    )
                self._cond.wait(min(left, 0.5))

    def describe(self) -> str:
        """The last lines of both streams: what an assertion about this child should show."""
        with self._cond:
            return f"{self.cmd[:3]} stdout={self.out[-5:]} stderr={self.err[-10:]}"

    def interrupt(self) -> None:
        """Ctrl-C: SIGINT, as a terminal sends it."""
        self.proc.send_signal(signal.SIGINT)

    def wait(self, timeout: float = 10.0) -> int:
        """The exit code once the child ends (and its output is read)."""
        code = self.proc.wait(timeout)
        for reader in self._readers:
            reader.join(2.0)
        return code

    def stop(self, grace: float = 10.0) -> int | None:
        """SIGTERM, up to ``grace`` seconds to exit, then SIGKILL to it and its descendants; returns the
        exit code (None when it had to be killed)."""
        code: int | None = None
        if self.proc.poll() is None:
            self.proc.terminate()
            try:
                code = self.proc.wait(grace)
            except subprocess.TimeoutExpired:
                pass
        else:
            code = self.proc.returncode
        if code is None:
            kill_tree(self.proc)
        for reader in self._readers:
            reader.join(2.0)
        return code

    def kill(self) -> None:
        """SIGKILL to it and its descendants at once (no shutdown hooks run)."""
        kill_tree(self.proc)
        for reader in self._readers:
            reader.join(2.0)

    def __enter__(self) -> NodeProcess:
        return self

    def __exit__(self, *exc: object) -> None:
        self.kill()


class CatkinWorkspace:
    """A catkin workspace for tests (ours and a user's): packages written from text, our
    ``catkin_make`` run in it, and the environment its programs see (what sourcing ``devel/setup.bash``
    gives: the workspace's packages on ROS_PACKAGE_PATH, its generated Python on PYTHONPATH, devel/ on
    CMAKE_PREFIX_PATH) with
    the outer environment's ROS variables left out, so nothing from the caller's workspace leaks in.

        ws = CatkinWorkspace(tmp_path)
        ws.package("chat", {"package.xml": XML, "CMakeLists.txt": CMAKE, "scripts/talk.py": TALK},
                   executables=["scripts/talk.py"])
        assert ws.catkin_make().returncode == 0
        subprocess.run([...], env=ws.env(master_uri))
    """

    def __init__(self, root: str | os.PathLike[str]) -> None:
        self.root = Path(root)

    def package(self, name: str, files: dict[str, str], executables: Sequence[str] = ()) -> Path:
        """Write package ``name`` under ``src/``: ``files`` maps paths in the package to their text;
        the paths in ``executables`` are made executable (scripts rosrun and rostest start)."""
        pkg = self.root / "src" / name
        for relative, text in files.items():
            path = pkg / relative
            path.parent.mkdir(parents=True, exist_ok=True)
            path.write_text(text)
            if relative in executables:
                path.chmod(0o755)
        return pkg

    def env(self, master_uri: str | None = None) -> dict[str, str]:
        """The environment of a program run in this workspace (``ROS_HOME`` is ``ros_home/`` in it)."""
        env = {
            k: v
            for k, v in os.environ.items()
            if not k.startswith("ROS_") and k not in ("CMAKE_PREFIX_PATH", "NINJEMYS_CATKIN_CPP")
        }
        env.update(
            ROS_PACKAGE_PATH=str(self.root / "src"),
            ROS_HOME=str(self.root / "ros_home"),
            ROS_HOSTNAME="localhost",
            PYTHONPATH=str(self.root / "devel" / "lib" / "python3" / "dist-packages"),
            CMAKE_PREFIX_PATH=str(self.root / "devel"),  # where rosrun finds devel/lib/<pkg>/ programs
        )
        if master_uri is not None:
            env["ROS_MASTER_URI"] = master_uri
        return env

    def catkin_make(self, *args: str, timeout: float = 600.0) -> subprocess.CompletedProcess[str]:
        """Our ``catkin_make args`` in the workspace, its output captured (the caller asserts on it)."""
        return subprocess.run(
            [ninjemys_bin("catkin_make"), *args],
            cwd=self.root,
            env={k: v for k, v in self.env().items() if k not in ("PYTHONPATH", "CMAKE_PREFIX_PATH")},
            capture_output=True,
            text=True,
            timeout=timeout,
            check=False,
        )

"""roslaunch.parent: ROSLaunchParent, a whole launch run from a script (``start()`` returns once the
nodes are started; ``spin()`` waits for the launch to end; ``shutdown()`` stops it).

It is ninjemys's own launch session (the ``roslaunch`` command's: same plan, master auto-start,
parameters, supervision), run on a thread of the script instead of owning the process: no signal
handlers are installed, so the script's own Ctrl-C handling stays in place.
"""

from __future__ import annotations

import itertools
import sys
import threading
from collections.abc import Callable, Sequence
from typing import Any

from ninjemys.errors import NinjemysError
from ninjemys.launch.launcher import NO_PROCESSES, LaunchOptions, LaunchSession
from ninjemys.launch.plan import LaunchPlan, NodeSpec
from ninjemys.launch.runner import ProcessSpec, Supervisor
from ninjemys.launch.xml import load_launch
from ninjemys.master.client import MasterClient

from .core import RLException

__all__ = ["ROSLaunchParent"]

#: ROS 1's number of roslaunch XML-RPC workers (ours has none; kept for the signature)
NUM_WORKERS = 3
#: seconds a node has after SIGINT, then after SIGTERM, at shutdown: ROS 1's script defaults
DEFAULT_TIMEOUT_SIGINT = 15.0
DEFAULT_TIMEOUT_SIGTERM = 2.0


_counter = itertools.count(1)
_counter_lock = threading.Lock()


def next_process_number() -> int:
    """ROS 1 numbers node processes (``talker-3``) with one counter for the whole script process,
    across every launch and scripted node."""
    with _counter_lock:
        return next(_counter)


def renumber(spec: ProcessSpec, node: NodeSpec | None) -> str:
    """Number ``spec`` as ROS 1 numbers node processes and return ROS 1's process name, ``ns/name-N``
    with N the script-wide number. The spec keeps a file-safe form (``ns-name-N``) for its log files
    (``__log:=`` follows)."""
    old = spec.name
    base = node.resolved_name.lstrip("/") if node is not None else old.rsplit("-", 1)[0]
    name = f"{base}-{next_process_number()}"
    spec.name = name.replace("/", "-")
    spec.argv = [
        a.replace(f"{old}.log", f"{spec.name}.log") if a.startswith("__log:=") else a for a in spec.argv
    ]
    return name


def _merge(into: LaunchPlan, plan: LaunchPlan) -> None:
    """Add ``plan`` (one file with its own arguments) to the combined launch."""
    into.files += plan.files
    into.nodes += plan.nodes
    into.tests += plan.tests
    into.params.update(plan.params)
    into.clear_params += plan.clear_params
    into.machines.update(plan.machines)
    into.setup_commands += plan.setup_commands
    into.warnings += plan.warnings


def load_plan(roslaunch_files: Sequence[Any], roslaunch_strs: Sequence[str] | None = None) -> LaunchPlan:
    """One plan from files (each a path or ``(path, ["arg:=value", ...])``) and XML strings."""
    plan = LaunchPlan()
    try:
        for entry in roslaunch_files:
            path, args = (entry, []) if isinstance(entry, str) else (entry[0], list(entry[1]))
            _merge(plan, load_launch([path], argv=args))
        for text in roslaunch_strs or []:
            _merge(plan, load_launch([], xml_text=text))
    except NinjemysError as exc:
        raise RLException(str(exc)) from None
    return plan


class _ScriptSession(LaunchSession):
    """A launch session for a script's thread: no signal handlers; ``started`` is set once every
    process has been started (or the launch ended first); with ``keep_up`` it runs until shutdown
    even when it has no node (the master it may have started stays up)."""

    def __init__(
        self,
        plan: LaunchPlan,
        opts: LaunchOptions,
        run_id: str,
        keep_up: bool,
        listeners: Sequence[Any] = (),
    ) -> None:
        super().__init__(plan, opts)
        self.run_id = run_id
        self.keep_up = keep_up
        #: ROS 1's process listeners: ``process_died(name, exit_code)`` when a process ends
        self.listeners = list(listeners)
        self.started = threading.Event()
        self.stopping = False

    def _supervise(self, specs: list[ProcessSpec], log: Callable[[str], None]) -> int:
        if self._core is not None:  # a master we started carries the script's run id, as in ROS 1
            with MasterClient(self.env["ROS_MASTER_URI"], "/roslaunch") as client:
                client.set_param("/run_id", self.run_id)
        nodes = [s for s in specs if not s.is_core]
        plan_nodes = self.plan.nodes if len(self.plan.nodes) == len(nodes) else [None] * len(nodes)
        ros1_names = {}
        for spec, node in zip(nodes, plan_nodes, strict=True):
            ros1_names[spec.name] = renumber(spec, node)
        self.supervisor = Supervisor(specs, log=log, prefix_output=self.opts.prefix_output)
        pending = {s.name for s in specs if not s.is_core}

        def on_event(kind: str, name: str) -> None:
            pending.discard(name)
            if not pending:
                self.started.set()
            if kind == "exited" and self.supervisor is not None:
                code = next((p.exit_code for p in self.supervisor.procs if p.spec.name == name), None)
                for listener in self.listeners:
                    listener.process_died(ros1_names.get(name, name), code)

        self.supervisor.on_event = on_event
        if not pending:
            self.started.set()
        if self.stopping:
            return 0
        if not specs and not self.keep_up:
            self._say(NO_PROCESSES)
            return 0
        return self.supervisor.run()


class ROSLaunchParent:
    """A launch of ``roslaunch_files`` (paths, or ``(path, [arg:=value ...])``) and ``roslaunch_strs``
    (XML texts), as ROS 1 scripts and rostest run them."""

    def __init__(
        self,
        run_id: str,
        roslaunch_files: Sequence[Any],
        is_core: bool = False,
        port: int | None = None,
        local_only: bool = False,
        process_listeners: Sequence[Any] | None = None,
        verbose: bool = False,
        force_screen: bool = False,
        force_log: bool = False,
        is_rostest: bool = False,
        roslaunch_strs: Sequence[str] | None = None,
        num_workers: int = NUM_WORKERS,
        timeout: float | None = None,
        master_logger_level: bool | str = False,
        show_summary: bool = True,
        force_required: bool = False,
        sigint_timeout: float = DEFAULT_TIMEOUT_SIGINT,
        sigterm_timeout: float = DEFAULT_TIMEOUT_SIGTERM,
    ) -> None:
        self.run_id = run_id
        self.roslaunch_files = roslaunch_files
        self.roslaunch_strs = roslaunch_strs
        self.is_core = is_core
        self.port = port
        self.local_only = local_only
        self.process_listeners = list(process_listeners or [])
        self.verbose = verbose
        self.is_rostest = is_rostest
        self.timeout = timeout
        self.options = LaunchOptions(
            screen=force_screen,
            log=force_log,
            port=port,
            required=force_required,
            local_only=local_only,
            no_summary=not show_summary,
            sigint_timeout=sigint_timeout,
            sigterm_timeout=sigterm_timeout,
        )
        self._session: _ScriptSession | None = None
        self._thread: threading.Thread | None = None
        self._error: BaseException | None = None
        self.exit_code: int | None = None
        #: set by start(): ROS 1 scripts test ``parent.runner`` before spinning
        self.runner: Any = None

    def _run(self) -> None:
        assert self._session is not None
        try:
            self.exit_code = self._session.run()
        except BaseException as exc:  # noqa: BLE001  (handed to start() on the script's thread)
            self._error = exc
            self.exit_code = 1
        finally:
            self._session.started.set()

    def start(self, auto_terminate: bool = True) -> None:
        """Load the files, start a master if none runs, set the parameters, start the nodes; returns
        once they are started. With ``auto_terminate`` the launch ends when its nodes have all exited."""
        if self._thread is not None:
            raise RLException("ROSLaunchParent has already been started")
        plan = load_plan(self.roslaunch_files, self.roslaunch_strs)
        self._session = _ScriptSession(
            plan, self.options, self.run_id, not auto_terminate, self.process_listeners
        )
        self._thread = threading.Thread(target=self._run, name="roslaunch", daemon=True)
        self._thread.start()
        self._session.started.wait()
        if self._error is not None:
            error, self._error = self._error, None
            raise RLException(str(error)) from None
        self.runner = self._session

    def spin_once(self) -> None:
        """ROS 1 runs one round of its process monitor here; ours runs on its own thread, so this
        only gives it the chance to report (nothing to do on the caller's thread)."""
        if self._thread is not None:
            self._thread.join(0.0)

    def is_alive(self) -> bool:
        """True while the launch runs."""
        return self._thread is not None and self._thread.is_alive()

    def spin(self) -> None:
        """Wait until the launch ends (Ctrl-C shuts it down), then clean up."""
        if self._thread is None:
            raise RLException("parent not started yet")
        try:
            while self._thread.is_alive():
                self._thread.join(0.2)
        except KeyboardInterrupt:
            pass
        finally:
            self.shutdown()

    def shutdown(self) -> None:
        """Stop every process (SIGINT, then SIGTERM, then SIGKILL) and the master it started."""
        session = self._session
        if session is None or self._thread is None:
            return
        session.stopping = True
        asked = False
        while self._thread.is_alive():  # the supervisor may not exist yet: ask once it does (a
            if not asked and session.supervisor is not None:  # second request would SIGKILL at once)
                session.supervisor.request_shutdown()
                asked = True
            self._thread.join(0.1)
        if self._error is not None and not isinstance(self._error, KeyboardInterrupt):
            print(f"roslaunch: {self._error}", file=sys.stderr)

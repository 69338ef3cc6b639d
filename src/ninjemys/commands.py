"""Our console scripts: where they are (roslaunch starts ``roscore`` this way, tests start every
command) and how each one ends (:func:`entry`: one-line errors on stderr, exit codes, no tracebacks).

The venv's ``bin/`` next to the running interpreter comes first, so a process started from a venv
runs that venv's commands even when another ROS (Debian's ``/usr/bin/roscore``) is on PATH.
"""

from __future__ import annotations

import os
import shutil
import signal
import sys
import threading
from collections.abc import Callable, Mapping

from ninjemys.errors import MasterUnreachable, NinjemysError


def command_path(command: str) -> str:
    """Full path of one of our console scripts; FileNotFoundError if it is not installed."""
    candidate = os.path.join(os.path.dirname(sys.executable), command)
    if os.path.exists(candidate):
        return candidate
    found = shutil.which(command)
    if found is None:
        raise FileNotFoundError(f"ninjemys command {command!r} is not installed next to {sys.executable}")
    return found


def with_our_commands(env: Mapping[str, str]) -> dict[str, str]:
    """``env`` with the directory of our console scripts first on PATH: what rosrun and roslaunch
    start (``$(find xacro)/xacro``, a shell script calling ``rostopic``) finds ninjemys' commands even
    when the venv is not activated, as ROS 1's are on PATH after its setup.bash."""
    out = dict(env)
    bindir = os.path.dirname(sys.executable)
    path = out.get("PATH", "")
    if bindir not in path.split(os.pathsep):
        out["PATH"] = os.pathsep.join([bindir, path]) if path else bindir
    return out


def error(message: str) -> None:
    """Print a user-facing error the way ROS 1 tools do (one line, stderr)."""
    print(message if message.startswith("ERROR") else f"ERROR: {message}", file=sys.stderr)


def answer_sigint() -> None:
    """Make Ctrl-C reach this process even when it was started with SIGINT ignored.

    A parent that ignores SIGINT passes that on through exec: a background job of a shell script, a
    supervisor that ignores Ctrl-C while it cleans up, a test runner. Python then leaves SIGINT ignored
    and never raises KeyboardInterrupt, so the process would not stop when roslaunch, a test or a user
    sends SIGINT. ROS 1's rospy and roscpp install their own handler at init, so their nodes and
    tools (rostopic, rosout, roscore) stop on SIGINT either way; ours do the same by restoring Python's
    default handler. Only the main thread may set handlers; elsewhere this does nothing.
    """
    if (
        threading.current_thread() is threading.main_thread()
        and signal.getsignal(signal.SIGINT) is signal.SIG_IGN
    ):
        signal.signal(signal.SIGINT, signal.default_int_handler)


def _terminated(_signum: int, _frame: object) -> None:
    raise KeyboardInterrupt


def answer_sigterm() -> None:
    """SIGTERM (``kill``, ``timeout 10 rostopic hz ...``) stops a tool as Ctrl-C does: its node
    unregisters from the master on the way out. rospy's tools do (rospy handles SIGTERM and shuts
    down); with the default action the process vanished and left its node registered. A tool that
    handles SIGTERM itself (roscore, roslaunch, a node's ``run_node``) sets its own handler later."""
    if (
        threading.current_thread() is threading.main_thread()
        and signal.getsignal(signal.SIGTERM) is signal.SIG_DFL
    ):
        signal.signal(signal.SIGTERM, _terminated)


def entry(main: Callable[[list[str] | None], int]) -> Callable[[], None]:
    """Wrap ``main`` for a console script: map our errors, Ctrl-C and SIGTERM to exit codes, never a
    traceback."""

    def console_main() -> None:
        answer_sigint()
        answer_sigterm()
        try:
            code = main(sys.argv[1:])
        except KeyboardInterrupt:
            code = 130 if os.environ.get("NINJEMYS_SIGINT_CODE") else 0
        except BrokenPipeError:
            # `rostopic echo /x | head`: the reader went away; exit quietly like ROS 1 tools
            devnull = os.open(os.devnull, os.O_WRONLY)
            os.dup2(devnull, sys.stdout.fileno())
            code = 1
        except MasterUnreachable:
            error("Unable to communicate with master!")
            code = 1
        except NinjemysError as exc:
            error(str(exc))
            code = 1
        sys.exit(code)

    return console_main

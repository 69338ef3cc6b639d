"""Running an in-house node as a process: name and remappings from the command line, Ctrl-C and
SIGTERM, spin until shutdown. One place for what every ``main()`` of a shipped node does."""

from __future__ import annotations

import os
import signal
import sys
import threading
from collections.abc import Callable
from typing import Any

from ninjemys.errors import NinjemysError, ShutdownError
from ninjemys.node.cli_args import network_env, parse_args
from ninjemys.node.node import Node


def start_node(default_name: str, argv: list[str] | None = None, anonymous: bool = False) -> Node:
    """A core Node named as ROS 1 names it from ``argv`` (``__name:=``, ``__ns:=``, ``__ip:=``,
    remappings, ``_private:=value`` parameters, ``__log:=``), on the process's default clock (sim
    time under /use_sim_time), with /rosout and the logger services, as ``rospy.init_node`` makes it.
    ``anonymous``: ``_<pid>_<ms>`` appended, as ROS 1's command-line tools (tf_echo, tf_monitor)
    register, so that two of them run side by side."""
    argv = sys.argv[1:] if argv is None else argv
    args = parse_args([sys.argv[0], *argv])
    os.environ.update(network_env(args))
    return Node(
        args.node_name(default_name, anonymous),  # ``__name:=`` wins over anonymous, as in rospy
        namespace=args.namespace,
        remappings=args.remappings,
        master_uri=args.master_uri,
        params=args.private_params,
        log_file=args.log_file,
        default_clock=True,
    )


def run_node(default_name: str, argv: list[str] | None, build: Callable[[Node], Any]) -> int:
    """Start the node, ``build(node)`` its parts, spin until Ctrl-C, SIGTERM or ``rosnode kill``.

    ``build`` returns a non-zero int to stop at once with that exit code (a required parameter that
    is missing). A signal shuts the node down from a ``shutdown`` thread, not from the interrupted
    main thread, which may hold locks the shutdown needs.
    """

    def build_and_spin(node: Node) -> int:
        code = build(node)
        if isinstance(code, int) and code:
            return code
        node.spin()
        return 0

    return run_main(default_name, argv, build_and_spin)


def run_main(
    default_name: str, argv: list[str] | None, body: Callable[[Node], int | None], anonymous: bool = False
) -> int:
    """Start the node and run ``body(node)`` on this thread (a node with a loop of its own: a keyboard
    teleop, a square driver), as :func:`run_node` does; returns its exit code (None: 0).

    Ctrl-C, SIGTERM and ``rosnode kill`` shut the node down (``node.is_shutdown`` turns True, its sleeps
    and rates raise ShutdownError, which ends ``body`` quietly); the node is shut down when ``body``
    returns, whichever way.
    """
    try:
        node = start_node(default_name, argv, anonymous)
    except NinjemysError as exc:
        print(f"{default_name}: {exc}", file=sys.stderr)
        return 1

    def on_signal(_signum: int, _frame: Any) -> None:
        threading.Thread(target=node.shutdown, args=("signal",), name="shutdown", daemon=True).start()

    if threading.current_thread() is threading.main_thread():
        signal.signal(signal.SIGINT, on_signal)
        signal.signal(signal.SIGTERM, on_signal)
    try:
        return body(node) or 0
    except ShutdownError:
        return 0
    finally:
        node.shutdown("exit")

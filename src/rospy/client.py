"""init_node and the module-level node API of rospy (names, parameters, spin, wait_for_message, ...).

``init_node`` reads the command line with :mod:`ninjemys.node.cli_args`, creates the core
:class:`~ninjemys.node.Node` (which sets up its own clock, logging, /rosout and logger services) and
installs signal handling. Every other function here forwards to that node and translates core errors
into rospy's exceptions.
"""

from __future__ import annotations

import atexit
import os
import signal
import sys
import threading
import time

from ninjemys import interrupt
from ninjemys.errors import MasterError, MasterUnreachable, NameError_, NinjemysError, ParameterError
from ninjemys.interrupt import wait_event
from ninjemys.node.log import INFO
from rospy._numpy_compat import restore_numpy_aliases
from rospy.core import _process, is_shutdown, signal_shutdown, warn_illegal_name
from rospy.exceptions import ROSException, ROSInitException, ROSInterruptException, mapped, translate

TYPE_CHECKING = False  # importing typing costs ~7 ms of every node's start-up; checkers set it
if TYPE_CHECKING:
    from typing import Any

__all__ = [
    "init_node",
    "spin",
    "myargv",
    "get_name",
    "get_namespace",
    "get_caller_id",
    "resolve_name",
    "remap_name",
    "get_param",
    "get_param_cached",
    "set_param",
    "has_param",
    "delete_param",
    "search_param",
    "get_param_names",
    "wait_for_message",
    "get_published_topics",
    "get_master",
]

_UNSPECIFIED = object()
_signals_installed = False
_process_hooks_installed = False
_signal_times: list[float] = []
#: a Ctrl-C arriving this long after the first one, while shutdown is still running, interrupts it
_INSIST_AFTER = 3.0


# -- init ---------------------------------------------------------------------------------------------------


def init_node(
    name: str,
    argv: list[str] | None = None,
    anonymous: bool = False,
    log_level: int | None = None,
    disable_rostime: bool = False,
    disable_rosout: bool = False,
    disable_signals: bool = False,
    xmlrpc_port: int = 0,
    tcpros_port: int = 0,
) -> None:
    """Register this process as ROS node ``name`` (a base name) with the master.

    ``anonymous=True`` appends ``_<pid>_<ms>`` so several copies can run; ``__name:=`` on the command
    line overrides both. ``log_level`` (rospy.DEBUG ... rospy.FATAL) sets the console and /rosout
    threshold. Unless ``disable_signals``, Ctrl-C (SIGINT) and SIGTERM shut the node down: sleeps
    raise ROSInterruptException and spin() returns. Calling it again with the same arguments is a no-op.
    """
    if argv is None:
        argv = sys.argv
    key = (name, argv, anonymous, log_level, disable_rostime, disable_signals)
    if not name:
        raise ValueError("name must not be empty")
    if "/" in name:
        raise ValueError("namespaces are not allowed in node names")
    with _process.lock:
        if _process.init_args is not None:
            if _process.init_args != key:
                raise ROSException(
                    f"rospy.init_node() has already been called with different arguments: {_process.init_args}"
                )
            return
        args = _parse(argv)
        base = args.node_name(name, anonymous)
        full = _node_name(base, args.namespace)
        from ninjemys.node.cli_args import network_env

        os.environ.update(network_env(args))
        if (
            not disable_signals
            and threading.current_thread() is threading.main_thread()
            and not _interactive()
        ):
            _install_signal_handlers()
        _install_process_hooks()
        restore_numpy_aliases()
        node = _start_node(full, args, log_level or INFO, not disable_rostime, not disable_rosout)
        _process.node = node
        _process.init_args = key
        node.on_shutdown(_on_node_shutdown)
        pending, _process.pending = _process.pending, []
    for handle in pending:
        handle._bind(node)
    if _process.shutdown_requested:
        node.shutdown("signal before init_node completed")
        raise ROSInitException("init_node interrupted before it could complete")


def _node_name(base: str, namespace: str) -> str:
    """The node's global name for ``base``, with rospy's warning (not an error) for an illegal one.

    rospy lets ``init_node("Wheel's velocity")`` (or ``__name:=a/b``) through with a UserWarning at
    the caller's line, and names the node by resolving ``base`` as ``<ns>/unnamed`` would
    (``~x`` -> ``/unnamed/x``); the master then refuses what it refuses (spaces, colons).
    """
    from ninjemys import names

    if not names.is_legal_base_name(base):
        import warnings

        warnings.warn(
            f"'{base}' is not a legal ROS base name. This may cause problems with other ROS tools.",
            stacklevel=3,  # warn in _node_name, called by init_node, called on the user's line
        )
    return names.resolve_name(base, names.canonicalize_name(namespace + "unnamed"))


def _parse(argv: list[str]) -> Any:
    from ninjemys.node.cli_args import parse_args

    try:
        return parse_args(argv, strict_names=False)
    except ParameterError as exc:
        raise ROSInitException(str(exc)) from None
    except NameError_ as exc:
        raise ValueError(str(exc)) from None


def _start_node(base: str, args: Any, log_level: int, rostime: bool, rosout: bool) -> Any:
    """The process's node: registered, its clock following /clock under /use_sim_time, /rosout and
    ``~get_loggers``/``~set_logger_level`` registered with the master before it returns (ROS 1)."""
    from ninjemys.node import Node

    try:
        return Node(
            base,
            namespace=args.namespace,
            remappings=args.remappings,
            master_uri=args.master_uri,
            params=args.private_params,
            sim_time="auto" if rostime else False,
            clock=_process.preinit_clock,
            rosout=rosout,
            log_level=log_level,
            log_file=args.log_file,
            default_clock=True,
            strict_names=False,
        )
    except NameError_ as exc:
        raise ValueError(str(exc)) from None
    except NinjemysError as exc:
        raise ROSInitException(f"init_node: {exc}") from None


def _on_node_shutdown() -> None:
    """The node is going down (for whatever reason): user hooks, then wake every sleeper."""
    _process.shutdown_requested = True
    _process.run_hooks()
    with _process.lock:
        waiters = list(_process.waiters)
    for event in waiters:
        event.set()


def _at_exit() -> None:
    """Process exit: shut the node down, or wait for a shutdown already under way (e.g. started by
    Ctrl-C on a helper thread) to finish unregistering, so the master is left clean."""
    node = _process.node
    if node is not None:
        if node.is_shutdown:
            node.shutdown("atexit")
        else:
            signal_shutdown("atexit")
    _process.log.close()


def _install_process_hooks() -> None:
    """Once per process: shut the node down at exit, keep interrupted callbacks quiet."""
    global _process_hooks_installed
    if _process_hooks_installed:
        return
    _process_hooks_installed = True
    atexit.register(_at_exit)
    _quiet_interrupted_callbacks()


# -- signals --------------------------------------------------------------------------------------------


def _quiet_interrupted_callbacks() -> None:
    """A callback interrupted by shutdown (``rospy.sleep`` inside it) ends quietly, as in rospy.

    The core logs any exception escaping a subscriber callback; a filter on that logger drops the
    ROSInterruptException ones once the node is shutting down, so delivery costs no wrapper call.
    """
    import logging

    def keep(record: logging.LogRecord) -> bool:
        exc = record.exc_info[0] if record.exc_info else None
        return not (exc is not None and issubclass(exc, ROSInterruptException) and is_shutdown())

    logging.getLogger("ninjemys.node.subscriber").addFilter(keep)


def _interactive() -> bool:
    """A REPL or notebook owns Ctrl-C (rospy leaves signals alone there too)."""
    return hasattr(sys, "ps1") or "IPython" in sys.modules


def _install_signal_handlers() -> None:
    global _signals_installed
    if _signals_installed:
        return
    _signals_installed = True
    for signum in (signal.SIGINT, signal.SIGTERM):
        previous = signal.getsignal(signum)
        signal.signal(signum, _make_handler(previous))


def _make_handler(previous: Any) -> Any:
    def handler(signum: int, frame: Any) -> None:
        if _process.shutdown_requested:
            # Another signal while shutting down (roslaunch and terminals often send two): ignore it,
            # unless the shutdown has been stuck for a while and the user insists with Ctrl-C.
            started = _signal_times[0] if _signal_times else time.monotonic()
            if signum == signal.SIGINT and time.monotonic() - started > _INSIST_AFTER:
                raise KeyboardInterrupt
            return
        _signal_times.append(time.monotonic())
        _process.shutdown_requested = True
        # Shut down on a helper thread: the interrupted main thread may hold locks the shutdown needs.
        threading.Thread(
            target=signal_shutdown, args=(f"signal-{signum}",), name="rospy-signal", daemon=True
        ).start()
        if callable(previous) and previous not in (
            signal.default_int_handler,
            signal.SIG_DFL,
            signal.SIG_IGN,
        ):
            previous(signum, frame)

    return handler


# -- spinning and args ----------------------------------------------------------------------------------


def spin() -> None:
    """Block until the node shuts down (Ctrl-C, rosnode kill, a name collision, signal_shutdown)."""
    node = _process.node
    if node is None:
        raise ROSInitException("client code must call rospy.init_node() first")  # rospy's words
    try:
        node.wait_for_shutdown()
    except KeyboardInterrupt:
        signal_shutdown("keyboard interrupt")


def myargv(argv: list[str] | None = None) -> list[str]:
    """``argv`` (default sys.argv) without ROS remapping arguments (``x:=y``)."""
    from ninjemys import names

    return names.strip_remap_args(sys.argv if argv is None else argv)


# -- names ----------------------------------------------------------------------------------------------


def get_name() -> str:
    """The node's fully resolved name (``/unnamed`` before init_node)."""
    node = _process.node
    return "/unnamed" if node is None else node.name


get_caller_id = get_name


def get_namespace() -> str:
    """The node's namespace, always ending with ``/``."""
    node = _process.node
    if node is None:
        from ninjemys import names

        return names.get_ros_namespace(argv=sys.argv)
    return node.namespace


def resolve_name(name: str, caller_id: str | None = None) -> str:
    """Resolve ``name`` as this node (or ``caller_id``) sees it, applying remappings."""
    from ninjemys import names

    node = _process.node
    with mapped():
        if caller_id is not None:
            return names.resolve_name(name, caller_id, getattr(node, "remappings", None))
        if node is None:
            return names.resolve_name(name, get_namespace() + "unnamed")
        return node.resolve_name(name)


def remap_name(name: str, caller_id: str | None = None, resolved: bool = True) -> str:
    """The remapped form of ``name``, resolved; ``name`` itself, unresolved, when the command line
    does not remap it (rospy's contract: resolve only what is remapped)."""
    from ninjemys import names

    mappings = names.load_mappings(sys.argv)
    if name not in mappings:
        return name
    return names.resolve_name(mappings[name], caller_id or get_name())


# -- parameters -----------------------------------------------------------------------------------------


def _params() -> Any:
    """Who asks the parameter server: the node, or before init_node rospy's ``/unnamed`` caller."""
    from rospy.service import _client_context

    return _client_context()


def get_param(param_name: str, default: Any = _UNSPECIFIED) -> Any:
    """A parameter's value (``~name`` is private to the node); KeyError when unset and no default.

    As in rospy, this works before ``init_node`` too (as ``/unnamed``: ``~x`` is ``/unnamed/x``).
    """
    ctx = _params()
    try:
        if default is _UNSPECIFIED:
            return ctx.get_param(param_name)
        return ctx.get_param(param_name, default)
    except ParameterError:
        raise KeyError(param_name) from None
    except NinjemysError as exc:
        raise translate(exc) from None


get_param_cached = get_param


def set_param(param_name: str, param_value: Any) -> None:
    """Set a parameter (dicts set a whole namespace); an illegal name only warns, as in rospy."""
    warn_illegal_name(param_name)
    ctx = _params()
    with mapped():
        ctx.set_param(param_name, param_value)


def has_param(param_name: str) -> bool:
    ctx = _params()
    with mapped():
        return bool(ctx.has_param(param_name))


def delete_param(param_name: str) -> None:
    """Delete a parameter; KeyError when it is not set."""
    ctx = _params()
    try:
        ctx.delete_param(param_name)
    except ParameterError:
        raise KeyError(param_name) from None
    except NinjemysError as exc:
        raise translate(exc) from None


def search_param(param_name: str) -> str | None:
    """The closest parameter named ``param_name`` up the namespace tree, or None."""
    ctx = _params()
    with mapped():
        found: str | None = ctx.search_param(param_name)
        return found


def get_param_names() -> list[str]:
    ctx = _params()
    with mapped():
        return list(ctx.get_param_names())


# -- graph ----------------------------------------------------------------------------------------------


def wait_for_message(topic: str, topic_type: Any, timeout: float | None = None) -> Any:
    """Receive one message on ``topic``; ROSException after ``timeout`` seconds, ROSInterruptException on shutdown."""
    from rospy.topics import Subscriber

    node = _process.node  # None before init_node: rospy waits all the same (init_node may come)
    box: list[Any] = []
    got = interrupt.Event()

    def take(msg: Any) -> None:
        if not box:
            box.append(msg)
            got.set()

    timeout = _seconds(timeout)
    sub = Subscriber(topic, topic_type, take, queue_size=1)
    with _process.lock:
        _process.waiters.add(got)
    if node is not None and node.is_shutdown:
        got.set()
    try:
        wait_event(got, timeout)
    finally:
        with _process.lock:
            _process.waiters.discard(got)
        sub.unregister()
    if box:
        return box[0]
    if is_shutdown():
        raise ROSInterruptException("rospy shutdown")
    raise ROSException(f"timeout exceeded while waiting for message on topic {topic}")  # rospy's words


def _seconds(timeout: Any) -> float | None:
    """A timeout in seconds from rospy's accepted forms: None, a number or a rospy.Duration."""
    if timeout is None:
        return None
    to_sec = getattr(timeout, "to_sec", None)
    return float(to_sec() if to_sec is not None else timeout)


def get_published_topics(namespace: str = "/") -> list[list[str]]:
    """[[topic, type], ...] of every published topic under ``namespace``."""
    ctx = _params()  # works before init_node, as rospy's /unnamed
    try:
        return [list(x) for x in ctx.master.get_published_topics(namespace)]
    except MasterUnreachable as exc:
        raise translate(exc) from None  # rospy: the socket's error, as for parameters
    except MasterError as exc:
        raise ROSException(f"unable to get published topics: {exc}") from None


def get_master(env: Any = None) -> Any:
    """The master's XML-RPC API as this node (``get_master().getSystemState()`` -> [code, msg, value])."""
    from rospy.msproxy import MasterProxy

    node = _process.node
    if node is None:
        from ninjemys.node.cli_args import parse_args

        return MasterProxy(parse_args(sys.argv, env, strict_names=False).master_uri, "/unnamed")
    return MasterProxy(node.master_uri, node.name, node.resolve_name)

"""rospy.Service, rospy.ServiceProxy and rospy.wait_for_service over the core's TCPROS services.

As in rospy, a ServiceProxy and wait_for_service work without ``init_node`` (the rospy_tutorials
add_two_ints client never calls it): they then talk to the master as ``/unnamed``.
"""

from __future__ import annotations

import sys
import threading
from collections.abc import Callable, Mapping

from ninjemys import interrupt, names
from ninjemys.errors import NinjemysError, ServiceError
from ninjemys.interrupt import wait_event
from ninjemys.node.log import ERROR
from ninjemys.node.params import ParamAccess
from rospy.core import _process, warn_illegal_name
from rospy.exceptions import NotAServiceClassError, ServiceException, mapped, translate
from rospy.msg import AnyMsg

TYPE_CHECKING = False  # importing typing costs ~7 ms of every node's start-up; checkers set it
if TYPE_CHECKING:
    from typing import Any

__all__ = ["Service", "ServiceProxy", "ServiceException", "wait_for_service"]


def _check_service_class(service_class: Any, name: str) -> None:
    if not all(hasattr(service_class, a) for a in ("_type", "_md5sum", "_request_class", "_response_class")):
        raise NotAServiceClassError(f"service [{name}]: [{service_class}] is not a service class")


class _AnyService:
    """Stands in for an unknown service type when only probing for a service's presence (md5 ``*``)."""

    _type = "*"
    _md5sum = "*"
    _request_class = AnyMsg
    _response_class = AnyMsg


class _Unnamed(ParamAccess):
    """The surface a core ServiceProxy and the parameter calls need from a node, for calls made
    before init_node (as rospy's ``/unnamed`` caller): a master client, a caller id, name
    resolution (``~x`` is ``/unnamed/x``, as in rospy), and interruptible waits."""

    def __init__(self) -> None:
        from ninjemys.master.client import MasterClient
        from ninjemys.node.cli_args import parse_args

        args = parse_args(sys.argv, strict_names=False)  # rospy checks no name before init_node
        self.name = names.canonicalize_name(args.namespace + "unnamed")
        self.remappings = args.resolved_remappings(self.name)
        self.master = MasterClient(args.master_uri, self.name)
        self._stop = interrupt.Event()

    @property
    def is_shutdown(self) -> bool:
        return self._stop.is_set()

    def wait_for_shutdown(self, timeout: float | None = None) -> bool:
        return wait_event(self._stop, timeout)

    def resolve_name(self, name: str) -> str:
        return names.resolve_name(name, self.name, self.remappings)


def _client_context() -> Any:
    """The node to call the master and services from: the initialized node, else the process's
    ``/unnamed`` context (made on first use, forgotten by ``reset_rospy``)."""
    node = _process.node
    if node is not None:
        return node
    with _process.lock:
        if _process.unnamed is None:
            _process.unnamed = _Unnamed()
        return _process.unnamed


def _core_proxy(name: str, service_class: Any, persistent: bool, headers: Mapping[str, str] | None) -> Any:
    ctx = _client_context()
    if ctx is _process.node:
        return ctx.service_proxy(name, service_class, persistent=persistent, headers=headers)
    from ninjemys.node.services import ServiceProxy as CoreProxy

    return CoreProxy(ctx, ctx.resolve_name(name), service_class, persistent, headers)


def wait_for_service(service: str, timeout: float | None = None) -> None:
    """Block until ``service`` is available; ROSException after ``timeout`` seconds."""
    from rospy.client import _seconds

    with mapped():
        _core_proxy(service, _AnyService, False, None).wait_for_service(_seconds(timeout))


class ServiceProxy:
    """Call service ``name``: ``proxy(req)`` or ``proxy(a=1, b=2)``; ServiceException on failure."""

    def __init__(
        self,
        name: str,
        service_class: Any,
        persistent: bool = False,
        headers: Mapping[str, str] | None = None,
    ) -> None:
        _check_service_class(service_class, name)
        self.service_class = service_class
        self.request_class = service_class._request_class
        self.response_class = service_class._response_class
        self.persistent = persistent
        self.headers = dict(headers or {})
        self.name = name
        self.resolved_name = _client_context().resolve_name(name)
        self._impl: Any = None
        self._lock = threading.Lock()

    def _core(self) -> Any:
        impl = self._impl
        if impl is None:
            with self._lock:
                if self._impl is None:
                    with mapped():
                        self._impl = _core_proxy(self.name, self.service_class, self.persistent, self.headers)
                impl = self._impl
        return impl

    def wait_for_service(self, timeout: float | None = None) -> None:
        from rospy.client import _seconds

        with mapped():
            self._core().wait_for_service(_seconds(timeout))

    def call(self, *args: Any, **kwds: Any) -> Any:
        """Send a request (an instance, or its fields) and return the response."""
        impl = self._impl or self._core()  # per call: no extra frame once the core proxy exists
        try:
            return impl.call(*args, **kwds)
        except NinjemysError as exc:
            raise translate(exc) from None

    __call__ = call  # proxy(...) is call(...) without a forwarding frame

    def __init_subclass__(cls, **kwargs: Any) -> None:
        # as in rospy, proxy(...) must reach a subclass's own call()
        super().__init_subclass__(**kwargs)
        if "call" in vars(cls) and "__call__" not in vars(cls):
            cls.__call__ = lambda self, *args, **kwds: self.call(*args, **kwds)  # type: ignore[method-assign]

    def close(self) -> None:
        """Close a persistent connection."""
        impl, self._impl = self._impl, None
        if impl is not None:
            impl.close()


class Service:
    """Serve ``name`` with ``handler(request) -> response`` (or a dict, tuple or single value).

    A handler raising ServiceException sends its message to the caller; any other exception is logged
    with its traceback (or passed to ``error_handler``) and reported to the caller as an error.
    """

    def __init__(
        self,
        name: str,
        service_class: Any,
        handler: Callable[[Any], Any],
        buff_size: int = 65536,
        error_handler: Callable[..., Any] | None = None,
    ) -> None:
        if not isinstance(name, str) or not name:
            raise ValueError("service name is not a non-empty string")
        _check_service_class(service_class, name)
        warn_illegal_name(name)
        self.service_class = service_class
        self.request_class = service_class._request_class
        self.response_class = service_class._response_class
        self.handler = handler
        self.error_handler = error_handler
        self.buff_size = buff_size
        self._requested = name
        self.resolved_name = self.name = _client_context().resolve_name(name)
        self._impl: Any = None
        self._unregistered = False
        _process.attach(self)

    def _bind(self, node: Any) -> None:
        if self._unregistered:
            return
        with mapped():
            self._impl = node.service(self._requested, self.service_class, self._handle)
        self.resolved_name = self.name = self._impl.resolved_name

    def _handle(self, request: Any) -> Any:
        try:
            return self.handler(request)
        except ServiceException as exc:
            # the core words a ServiceError as rospy does: "service cannot process request: ..."
            raise ServiceError(str(exc)) from None
        except Exception as exc:
            if self.error_handler is not None:
                self.error_handler(exc, *sys.exc_info())
            else:
                _process.log.log(ERROR, "Error processing request: %s", exc, exc_info=True)
            exc.ninjemys_reported = True  # type: ignore[attr-defined]  # the core need not log it again
            raise

    def shutdown(self, reason: str = "") -> None:
        """Stop serving and unregister from the master."""
        self._unregistered = True
        impl, self._impl = self._impl, None
        if impl is not None:
            impl.shutdown()
        with _process.lock:
            if self in _process.pending:
                _process.pending.remove(self)

    unregister = shutdown

    def spin(self) -> None:
        """Block until the node shuts down (rospy.Service.spin)."""
        from rospy.client import spin

        spin()

"""rospy.Publisher and rospy.Subscriber: handles that bind to the process's node.

They may be created before ``init_node`` (the seeds' talker builds its Publisher first): the handle
then waits in the facade's pending list and is created on the node during ``init_node``, with the
node's final name, namespace and remappings. All transport behaviour is the core's.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping

from ninjemys.errors import NinjemysError, SerializationError, ShutdownError
from rospy.core import _process, is_shutdown, warn_illegal_name
from rospy.exceptions import (
    PublishArgumentError,
    ROSException,
    ROSInterruptException,
    ROSSerializationException,
    translate,
)
from rospy.msg import AnyMsg, args_kwds_to_message

TYPE_CHECKING = False  # importing typing costs ~7 ms of every node's start-up; checkers set it
if TYPE_CHECKING:
    from typing import Any

__all__ = ["Publisher", "Subscriber", "SubscribeListener", "Topic"]


def _check_class(data_class: Any, what: str) -> None:
    if data_class is None:
        raise ValueError(f"{what}: data_class must not be None")
    if not hasattr(data_class, "_type") or not hasattr(data_class, "_md5sum"):
        raise ValueError(f"{what}: data_class [{data_class}] is not a message class")


def _resolved(name: str) -> str:
    """The name as resolved now (before init_node: in the namespace, as ``/unnamed``, like rospy)."""
    from rospy.client import resolve_name

    return resolve_name(name)


class SubscribeListener:
    """Accepted for API compatibility: rospy calls it on peer (un)subscription."""

    def peer_subscribe(self, topic_name: str, topic_publish: Any, peer_publish: Any) -> None:
        pass

    def peer_unsubscribe(self, topic_name: str, num_peers: int) -> None:
        pass


class Topic:
    """What Publisher and Subscriber share: the name, the message type and the core handle.

    Subclasses provide ``_create(node)``, which makes the core handle.
    """

    def __init__(self, name: str, data_class: Any) -> None:
        if not isinstance(name, str) or not name:
            raise ValueError(f"topic name must be a non-empty string, not {name!r}")
        _check_class(data_class, f"topic [{name}]")
        warn_illegal_name(name, stacklevel=4)  # the user's Publisher(...)/Subscriber(...) line
        self._requested = name
        self.data_class = data_class
        self.type = data_class._type
        self.md5sum = data_class._md5sum
        self.resolved_name = _resolved(name)
        self.name = self.resolved_name
        self._impl: Any = None
        self._unregistered = False

    def get_num_connections(self) -> int:
        """Number of peers connected right now (0 before init_node)."""
        impl = self._impl
        return 0 if impl is None else impl.get_num_connections()

    def unregister(self) -> None:
        """Stop publishing/subscribing and tell the master."""
        self._unregistered = True
        impl, self._impl = self._impl, None
        if impl is not None:
            try:
                impl.unregister()
            except NinjemysError as exc:
                raise translate(exc) from None
        with _process.lock:
            if self in _process.pending:
                _process.pending.remove(self)

    def _bind(self, node: Any) -> None:
        if self._unregistered:
            return
        try:
            self._impl = self._create(node)
        except ShutdownError:
            if not is_shutdown():
                raise ROSInterruptException(f"topic [{self.resolved_name}]: the node is shut down") from None
            # as rospy: a handle made while the node shuts down exists, and sends or receives nothing
            return
        except NinjemysError as exc:
            raise translate(exc) from None
        self.resolved_name = self.name = self._impl.resolved_name


class Publisher(Topic):
    """Publish messages of ``data_class`` on topic ``name``.

    ``queue_size=None`` publishes synchronously (blocks, never drops); ``queue_size=N`` drops the oldest
    per connection; ``latch=True`` resends the last message to late subscribers.
    """

    def __init__(
        self,
        name: str,
        data_class: Any,
        subscriber_listener: SubscribeListener | None = None,
        tcp_nodelay: bool = False,
        latch: bool = False,
        headers: Mapping[str, str] | None = None,
        queue_size: int | None = None,
    ) -> None:
        super().__init__(name, data_class)
        if queue_size is None:
            import warnings

            warnings.warn(
                "The publisher should be created with an explicit keyword argument 'queue_size'. "
                "Please see http://wiki.ros.org/rospy/Overview/Publishers%20and%20Subscribers for more "
                "information.",
                SyntaxWarning,
                stacklevel=2,
            )
        self.subscriber_listener = subscriber_listener
        self.tcp_nodelay = tcp_nodelay
        self.latch = latch
        self.headers = dict(headers or {})
        self.queue_size = queue_size
        self._raw = data_class is AnyMsg
        #: publish's fast path takes messages of exactly this class (None for AnyMsg: never)
        self._plain_class = None if self._raw else data_class
        _process.attach(self)

    def _create(self, node: Any) -> Any:
        return node.publisher(
            self._requested,
            self.data_class,
            queue_size=self.queue_size,
            latch=self.latch,
            tcp_nodelay=self.tcp_nodelay,
            headers=self.headers or None,
        )

    def publish(self, *args: Any, **kwds: Any) -> None:
        """Publish a message, or build one from the arguments: ``pub.publish("hello")`` for a String."""
        impl = self._impl
        if impl is not None and not kwds and len(args) == 1 and args[0].__class__ is self._plain_class:
            # the common case first (a message of the topic's own class, not AnyMsg): fewer checks
            publication = impl.publication
            if publication.connections or publication.intra or self.latch:
                try:
                    impl.publish(args[0])
                except NinjemysError as exc:
                    self._publish_failed(exc)
            return
        if impl is None:
            self._not_ready()  # raises, unless the node is shutting down (then nothing is sent)
            return
        if len(args) == 1 and not kwds and isinstance(args[0], self.data_class):
            msg = args[0]
        else:
            try:
                msg = args_kwds_to_message(self.data_class, args, kwds)
            except TypeError as exc:
                raise PublishArgumentError(str(exc)) from None
            except ValueError as exc:
                raise ROSSerializationException(str(exc)) from None
        # as rospy: nobody listens, so nothing is serialized (a bad field is not an error yet); the
        # publication's tuples read directly (a call to get_num_connections per publish is ~10 % of a
        # small message's whole cost in a flood)
        publication = impl.publication
        if not (self.latch or publication.connections or publication.intra):
            return
        try:
            if self._raw:
                impl.publish_raw(msg._buff)
            else:
                impl.publish(msg)
        except NinjemysError as exc:
            self._publish_failed(exc)

    def _publish_failed(self, exc: NinjemysError) -> None:
        """rospy's exception for a failed publish (raised from the handler of ``exc``)."""
        try:
            raise exc
        except ShutdownError:
            if is_shutdown():
                return  # as rospy: publishing while the node shuts down is quietly dropped
            raise ROSInterruptException(f"publish() to a closed topic [{self.resolved_name}]") from None
        except SerializationError as exc:
            raise ROSSerializationException(str(exc)) from None
        except NinjemysError as exc:
            raise translate(exc) from None

    def loan(self, length: int, field: str | None = None, **fields: Any) -> Any:
        """ninjemys' addition: a message whose ``uint8[]`` array of ``length`` bytes is written straight
        into a shared-memory slot of a same-host subscriber (``with pub.loan(n, ...) as msg: fill
        msg.data; pub.publish(msg)``); see ``ninjemys.node.shm_loan`` for the rules."""
        impl = self._impl
        if impl is None:
            self._not_ready()
            raise ROSException(f"loan() from a closed topic [{self.resolved_name}]")
        try:
            return impl.loan(length, field, **fields)
        except NinjemysError as exc:
            raise translate(exc) from None

    def _not_ready(self) -> None:
        if self._unregistered:
            raise ROSException(f"publish() to an unregistered() handle [{self.resolved_name}]")
        if _process.node is None:
            raise ROSException("ROS node has not been initialized yet. Please call init_node() first")
        if is_shutdown():
            return  # as rospy: publishing while the node shuts down is quietly dropped
        raise ROSInterruptException(f"publish() to a closed topic [{self.resolved_name}]")


class Subscriber(Topic):
    """Call ``callback(msg)`` (or ``callback(msg, callback_args)``) for each message on ``name``.

    The callback runs on this subscription's own thread; ``queue_size`` bounds the messages waiting
    for it (the oldest are dropped, never deserialized). ``buff_size`` and ``tcp_nodelay`` are accepted
    for compatibility: the core reads whole messages and always sets TCP_NODELAY.
    """

    def __init__(
        self,
        name: str,
        data_class: Any,
        callback: Callable[..., Any] | None = None,
        callback_args: Any = None,
        queue_size: int | None = None,
        buff_size: int = 65536,
        tcp_nodelay: bool = False,
    ) -> None:
        super().__init__(name, data_class)
        self.callback = callback
        self.callback_args = callback_args
        self.queue_size = queue_size
        self.buff_size = buff_size
        self.tcp_nodelay = tcp_nodelay
        _process.attach(self)

    def _create(self, node: Any) -> Any:
        callback = self.callback
        raw = self.data_class is AnyMsg
        if raw and callback is not None:
            callback = _any_msg_adapter(callback)
        return node.subscriber(
            self._requested,
            None if raw else self.data_class,
            callback,
            callback_args=self.callback_args,
            queue_size=self.queue_size,
            raw=raw,
        )


def _any_msg_adapter(callback: Callable[..., Any]) -> Callable[..., Any]:
    """Deliver AnyMsg instances (bytes in ``_buff``) instead of the core's RawMessage."""

    def deliver(raw: Any, *args: Any) -> Any:
        msg = AnyMsg()
        msg._buff = raw.data
        msg._connection_header = dict(raw.connection_header)
        return callback(msg, *args)

    return deliver

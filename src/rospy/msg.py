"""AnyMsg (a message of any type, kept serialized) and rospy's implicit message construction."""

from __future__ import annotations

from rospy.exceptions import ROSException, ROSSerializationException

TYPE_CHECKING = False  # importing typing costs ~7 ms of every node's start-up; checkers set it
if TYPE_CHECKING:
    from typing import Any

__all__ = ["AnyMsg", "args_kwds_to_message"]


class AnyMsg:
    """A message whose type is not known in advance: ``_buff`` holds its serialized bytes.

    Subscribing with AnyMsg relays or records topics of any type; publishing one sends its bytes as is.
    """

    _md5sum = "*"
    _type = "*"
    _has_header = False
    _full_text = ""
    __slots__ = ["_buff", "_connection_header"]

    def __init__(self, *args: Any) -> None:
        if args:
            raise ROSException("AnyMsg does not accept arguments")
        self._buff: bytes | bytearray | None = None
        self._connection_header: dict[str, str] = {}

    def serialize(self, buff: Any) -> None:
        if self._buff is None:
            raise ROSSerializationException("AnyMsg is not initialized")
        buff.write(self._buff)

    def serialize_to_bytes(self) -> bytes:
        if self._buff is None:
            raise ROSSerializationException("AnyMsg is not initialized")
        return bytes(self._buff)

    def deserialize(self, data: bytes | bytearray) -> AnyMsg:
        self._buff = data
        return self

    @classmethod
    def deserialize_from(cls, data: bytes | bytearray | memoryview) -> AnyMsg:
        msg = cls()
        msg._buff = bytes(data)
        return msg


def args_kwds_to_message(data_class: Any, args: tuple[Any, ...], kwds: dict[str, Any]) -> Any:
    """Build a ``data_class`` from publish()'s arguments, with rospy's rules.

    ``pub.publish("hi")`` makes ``String("hi")``; a single message of the right type (same md5) or an
    AnyMsg is used as is; a single message of another type must match the first field's type.
    """
    if args and kwds:
        raise TypeError("publish() can be called with arguments or keywords, but not both.")
    if kwds:
        return data_class(**kwds)
    if len(args) == 1:
        arg = args[0]
        if hasattr(arg, "_md5sum") and (arg._md5sum == data_class._md5sum or isinstance(arg, AnyMsg)):
            return arg
        if hasattr(arg, "_type") and hasattr(arg, "_slot_types"):
            slot_types = getattr(data_class, "_slot_types", ())
            if not slot_types:
                raise TypeError(f"expected [] but got [{arg._type}]")
            if arg._type != slot_types[0]:
                raise TypeError(f"expected [{slot_types[0]}] but got [{arg._type}]")
    return data_class(*args)

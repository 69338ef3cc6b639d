"""rospy.numpy_msg: message classes whose numeric arrays are numpy arrays.

ninjemys' generated classes already (de)serialize numeric arrays through numpy views, so
``numpy_msg(Floats)`` returns a subclass whose ``deserialize`` yields arrays and whose ``serialize``
accepts them, mirroring rospy.numpy_msg.numpy_msg.
"""

from __future__ import annotations

TYPE_CHECKING = False  # importing typing costs ~7 ms of every node's start-up; checkers set it
if TYPE_CHECKING:
    from typing import Any


__all__ = ["numpy_msg"]

_cache: dict[type, type] = {}


def numpy_msg(msg_type: type) -> type:
    """A subclass of ``msg_type`` that uses the numpy (de)serializers."""
    cached = _cache.get(msg_type)
    if cached is not None:
        return cached

    fields = list(msg_type.__slots__)

    def _decoded(data: Any) -> Any:
        return msg_type().deserialize_numpy(bytes(data), _numpy())

    def deserialize(self: Any, data: Any) -> Any:
        plain = _decoded(data)
        for name in fields:
            setattr(self, name, getattr(plain, name))
        return self

    @classmethod  # type: ignore[misc]
    def deserialize_from(cls: type, data: Any) -> Any:
        return deserialize(cls.__new__(cls), data)

    # serialization needs no override: the generated serializers accept numpy arrays as they are
    namespace = {
        "__slots__": [],
        "_numpy_msg": True,
        "deserialize": deserialize,
        "deserialize_from": deserialize_from,
    }
    cls = type(f"Numpy_{msg_type.__name__}", (msg_type,), namespace)
    _cache[msg_type] = cls
    return cls


def _numpy() -> Any:
    import numpy

    return numpy
